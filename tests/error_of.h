// The message a refray::Error carries, for tests of error texts.
#pragma once

#include <string>

#include "core/error.h"

namespace refray::testing {

// What `f` throws as a refray::Error, or "(no error)" when it returns normally.
template <typename F>
std::string errorOf(F&& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no error)";
}

}  // namespace refray::testing
