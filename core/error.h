// Errors: one exception type for bad input and API misuse, an assertion for our own bugs.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace refray {

// Bad input or API misuse. The message says what was wrong and, where known, where
// (file:line, pixel, export) — it is meant to be read by the person who caused it.
class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

namespace detail {
[[noreturn]] void assertionFailed(const char* expression, const char* file, int line, const std::string& values);
}  // namespace detail

}  // namespace refray

// REFRAY_CHECK(cond, "stream" << values): throws refray::Error with the streamed message.
#define REFRAY_CHECK(condition, message)                                   \
    do {                                                                   \
        if (!(condition)) {                                                \
            std::ostringstream refray_check_stream_;                       \
            refray_check_stream_ << message;                               \
            throw ::refray::Error(refray_check_stream_.str());             \
        }                                                                  \
    } while (false)

// REFRAY_ASSERT(cond, "stream" << values): our own logic error; prints and aborts in every build.
#define REFRAY_ASSERT(condition, message)                                              \
    do {                                                                               \
        if (!(condition)) {                                                            \
            std::ostringstream refray_assert_stream_;                                  \
            refray_assert_stream_ << message;                                          \
            ::refray::detail::assertionFailed(#condition, __FILE__, __LINE__,          \
                                              refray_assert_stream_.str());            \
        }                                                                              \
    } while (false)
