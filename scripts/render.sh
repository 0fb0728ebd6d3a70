#!/usr/bin/env bash
# Installs dependencies and builds when needed, then renders a scene (default: the bundled Cornell
# box, written to cornell-box.png in the current folder). Extra arguments go to `penumbra render`.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/build.sh" >&2
if [ $# -eq 0 ]; then
  exec "$root/build/bin/penumbra"
fi
exec "$root/build/bin/penumbra" render "$@"
