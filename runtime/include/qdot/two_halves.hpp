// inTwoHalves: a large loop whose iterations write only their own elements, split between this
// thread and a second one (issue 15). The compiler is single-threaded and a large model's stages
// spend their time writing one object per array element (symbols, variables) at 1-2 GB/s: the
// second core, idle during the compile, makes half of them. The run time's passes over a large
// model's pattern and vectors before IDA starts are split the same way. Small loops stay on this
// thread.
#pragma once

#include <cstddef>
#include <thread>

namespace qdot {

/// Iterations from which inTwoHalves uses a second thread (a thread costs ~50 µs to start).
inline constexpr size_t kTwoHalvesFrom = size_t{1} << 16;

/// Calls body(begin, end) on [0, count): for count >= kTwoHalvesFrom as [0, count/2) here and
/// [count/2, count) on a second thread, joined before returning. body must write nothing that
/// another iteration reads or writes, and read nothing that is written meanwhile.
template <class Body>
void inTwoHalves(size_t count, Body&& body) {
  if (count < kTwoHalvesFrom) {
    body(size_t{0}, count);
    return;
  }
  std::thread second([&body, count] { body(count / 2, count); });
  body(size_t{0}, count / 2);
  second.join();
}

}  // namespace qdot
