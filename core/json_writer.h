// A small JSON writer (RFC 8259), the counterpart of core/json.h's reader: builds one document as text,
// indented two spaces per level. Arrays opened with Layout::Inline (and everything inside them) stay on one
// line, which keeps vectors such as [1, 0.9, 0.7, 1] readable.
#pragma once

#include <concepts>
#include <cstdint>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace refray::json {

// `text` as a JSON string literal, quotes included: `"`, `\` and control characters escaped.
std::string quoted(std::string_view text);

class Writer {
public:
    enum class Layout { Indented, Inline };

    Writer& beginObject(Layout layout = Layout::Indented);
    Writer& endObject();
    Writer& beginArray(Layout layout = Layout::Indented);
    Writer& endArray();
    // The next value is this member of the open object.
    Writer& key(std::string_view name);

    Writer& value(std::string_view text);
    Writer& value(const char* text) { return value(std::string_view(text)); }
    Writer& value(const std::string& text) { return value(std::string_view(text)); }
    Writer& value(bool b);
    // Floating point: the shortest text that reads back as the same float (or double).
    // JSON has no NaN or infinity: those throw refray::Error.
    Writer& value(float number);
    Writer& value(double number);
    template <std::integral T>
        requires(!std::same_as<T, bool>)
    Writer& value(T number) {
        if constexpr (std::is_signed_v<T>) return signedValue(int64_t(number));
        else return unsignedValue(uint64_t(number));
    }
    Writer& null();

    // key(name).value(v) in one call.
    template <class T>
    Writer& member(std::string_view name, const T& v) {
        return key(name).value(v);
    }

    // The document; asserts that it is one complete value.
    const std::string& text() const;

private:
    struct Level {
        bool object = false;
        bool inlineLayout = false;
        bool empty = true;
        bool keyPending = false;
    };
    Writer& signedValue(int64_t number);
    Writer& unsignedValue(uint64_t number);
    void beforeValue();   // separator and indentation for a value about to be written
    Writer& raw(std::string_view token);
    Writer& open(char bracket, bool object, Layout layout);
    Writer& close(char bracket, bool object);
    void newline(size_t depth);

    std::string out_;
    std::vector<Level> levels_;
    bool done_ = false;
};

}  // namespace refray::json
