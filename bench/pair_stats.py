"""Statistics of alternated pairs, shared by the scripts of bench/ (vs-smallvcm.sh, ab-builds.sh).

A pair is two renders made one right after the other, so both see the same state of a machine whose
speed drifts; what is compared is the median of the pairs' ratios, with an interval for it that
holds whatever the distribution of the ratios.
"""
import math
import statistics


def median_interval(q, level=0.95):
    """The narrowest symmetric pair of order statistics [q(j), q(n-1-j)] that covers the median with
    probability >= level whatever the distribution: the count of values below the median is
    Binomial(n, 1/2). None when n is too small for the level (n < 6 at 95 %)."""
    q = sorted(q)
    n = len(q)
    best = None
    for j in range(n // 2 + 1):
        coverage = sum(math.comb(n, i) for i in range(j + 1, n - j)) / 2 ** n
        if coverage < level:
            break
        best = (q[j], q[n - 1 - j])
    return best


def describe_ratios(q, digits=3):
    """'median [95 % interval] (min-max)' of a list of ratios; '-' when empty."""
    if not q:
        return "-"
    ci = median_interval(q)
    interval = f"[{ci[0]:.{digits}f}, {ci[1]:.{digits}f}]" if ci else "[-]"
    return f"{statistics.median(q):.{digits}f} {interval} ({min(q):.{digits}f}-{max(q):.{digits}f})"
