#include "support/Assert.h"

#include <cstdio>
#include <cstdlib>

namespace qdot::detail {

void assertionFailed(const char* file, int line, const char* condition, const char* reason) {
  std::fprintf(stderr, "%s:%d: qdot internal error: %s (%s)\nthis is a bug in qdot; please report it with the model\n",
               file, line, reason, condition);
  std::fflush(stderr);
  std::abort();
}

}  // namespace qdot::detail
