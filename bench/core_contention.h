// A probe of how much of this processor core the program has to itself.
//
// On a virtual machine the host may run another guest's hardware thread on the same physical core
// (simultaneous multithreading). That guest then shares the core's front end and execution units
// with ours: code that issues many instructions per cycle slows down, while a chain of dependent
// operations, which waits on latency and uses little of the core, runs at the clock's pace. On this
// project's machine such phases come and go over seconds, and in them the path tracer slowed by
// about a third and raw Embree's traversal by about a sixth (docs/benchmarks.md, "What slows the
// path tracer more than Embree"). The probe times both kinds of loop in alternating parts; their
// quotient does not change with the clock and grows with the contention.
#pragma once

namespace penumbra::bench {

struct CoreContention {
  double call_ns = 0;   // per call of an out-of-line function, the calls independent (throughput)
  double chain_ns = 0;  // per step of a dependent multiply-add chain (latency: the clock only)
  /// call / chain, part by part (the loops alternate in parts): about constant on an idle core of a
  /// given processor, larger under contention.
  double index = 0;
};

/// Times `steps` of each loop on the calling thread (4 million: about 10 ms in all here), in eight
/// alternating parts; each figure is the median over the parts.
CoreContention probe_core(long steps = 4'000'000);

/// The largest index of `threads` probes run at the same time, one per thread, so that a contended
/// core among those a multi-threaded measurement runs on shows. Waits 10 ms first, for the thread
/// pool's workers to stop spinning.
double probe_cores(int threads, long steps = 4'000'000);

}  // namespace penumbra::bench
