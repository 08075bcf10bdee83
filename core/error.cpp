#include "core/error.h"

#include <cstdio>
#include <cstdlib>

namespace refray::detail {

void assertionFailed(const char* expression, const char* file, int line, const std::string& values) {
    // An internal invariant broke: this is a refray bug, not bad input.
    std::fprintf(stderr, "refray internal error: %s:%d: assertion '%s' failed: %s\n", file, line, expression,
                 values.c_str());
    std::abort();
}

}  // namespace refray::detail
