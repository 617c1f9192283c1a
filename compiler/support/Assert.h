// QDOT_ASSERT / QDOT_UNREACHABLE: the one way to state a compiler invariant. A failed assertion is a
// bug in qdot, never the user's error (user errors are diagnostics, see Diagnostic.h). Active in
// Debug builds and in fuzz builds (QDOT_FUZZ, where Release optimisation is wanted but a broken
// invariant must stop the run); it prints file:line, the condition and the reason, then aborts.
#pragma once

namespace qdot::detail {
[[noreturn]] void assertionFailed(const char* file, int line, const char* condition, const char* reason);
}  // namespace qdot::detail

#if !defined(NDEBUG) || defined(QDOT_FUZZ)
#define QDOT_ASSERT(cond, reason) \
  ((cond) ? static_cast<void>(0) : ::qdot::detail::assertionFailed(__FILE__, __LINE__, #cond, reason))
#else
#define QDOT_ASSERT(cond, reason) static_cast<void>(sizeof(static_cast<bool>(cond)))
#endif

/// Marks code the compiler's invariants make unreachable (e.g. after a switch over every enumerator).
/// Always fatal, also in Release: falling through would compute garbage.
#define QDOT_UNREACHABLE(reason) ::qdot::detail::assertionFailed(__FILE__, __LINE__, "unreachable", reason)
