// A small JSON reader (RFC 8259) that keeps the source position of every value and
// key, so that scene-file errors can say "file:line:column: what was wrong".
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace refray::json {

// 1-based line and column; the column counts bytes from the start of the line.
struct Location {
    std::string file;
    uint32_t line = 0;
    uint32_t column = 0;
};

// "file:line:column".
std::string toString(const Location& location);

struct Member;

namespace detail {
class Parser;
}

// One JSON value and, for arrays and objects, its children (owned by value).
// Accessors of the wrong kind throw refray::Error "FILE:LINE:COL: expected a number, got a string".
class Value {
public:
    enum class Kind { Null, Bool, Number, String, Array, Object };

    Value();  // null, with an empty location
    Value(const Value& other);
    Value(Value&& other) noexcept;
    Value& operator=(const Value& other);
    Value& operator=(Value&& other) noexcept;
    ~Value();

    Kind kind() const { return kind_; }
    const Location& location() const { return location_; }  // where the value starts
    // "null", "a boolean", "a number", "a string", "an array", "an object".
    std::string_view kindName() const;

    bool isNull() const { return kind_ == Kind::Null; }
    bool isBool() const { return kind_ == Kind::Bool; }
    bool isNumber() const { return kind_ == Kind::Number; }
    bool isString() const { return kind_ == Kind::String; }
    bool isArray() const { return kind_ == Kind::Array; }
    bool isObject() const { return kind_ == Kind::Object; }

    bool asBool() const;
    double asNumber() const;
    // The number rounded to float; an error if it is too large for one ("1e39 does not fit
    // in a 32-bit float"). Numbers too small for a float become 0.
    float asFloat() const;
    // Exact, from the source text: an error unless the number is an integer ("2", "2.0" and
    // "2e0" are) within the range of the result type.
    int64_t asInt() const;
    uint32_t asUint32() const;
    const std::string& asString() const;
    const std::vector<Value>& asArray() const;
    const std::vector<Member>& asObject() const;  // members in file order
    // The member's value, or nullptr if absent; an error if this is not an object.
    const Value* find(std::string_view key) const;
    // The number's exact source text (e.g. "15.8429795"), for provenance.
    const std::string& numberText() const;

    // Throws refray::Error("FILE:LINE:COL: " + message) at this value's location.
    [[noreturn]] void fail(const std::string& message) const;

private:
    friend class detail::Parser;
    friend void applyPatch(Value& document, const Value& patch);

    [[noreturn]] void failKind(std::string_view expected) const;

    Kind kind_ = Kind::Null;
    Location location_;
    bool bool_ = false;
    double number_ = 0.0;
    std::string text_;  // the string, or the number's source text
    std::vector<Value> array_;
    std::vector<Member> object_;
};

struct Member {
    std::string key;
    Location keyLocation;  // the key's opening quote
    Value value;
};

// Parses UTF-8 JSON text; `file` is the name used in locations. A leading UTF-8 byte
// order mark is skipped (columns on line 1 count from after it). Bad input throws
// refray::Error "FILE:LINE:COL: expected X, got Y" (or "unexpected end of file, expected X").
// Rejected: syntax errors, duplicate keys in one object (the message names both),
// nesting deeper than 256 arrays and objects, anything after the top-level value,
// comments, NaN/Infinity, invalid UTF-8 in strings, unpaired \u surrogates, and
// numbers too large for a double (numbers too small for one become 0).
Value parse(std::string_view text, std::string file);

// Reads the file (error "cannot read FILE: reason") and parses it, naming it path.string().
Value parseFile(const std::filesystem::path& path);

// Applies a JSON Patch (RFC 6902) of "replace", "add" and "remove" operations, with RFC 6901 JSON Pointer
// paths ("/instances/4/mask"; "-" appends to an array), to `document`, in order. Values taken from the patch keep
// the patch's locations, so later errors point at the line that introduced them. A bad operation throws
// refray::Error at its location naming the path and what is there.
void applyPatch(Value& document, const Value& patch);

// Reads an object member by member and reports keys nobody asked for. Keeps a pointer
// to `value`, which must outlive the reader.
class ObjectReader {
public:
    // `what` names the object in messages, e.g. "camera 'overview'". Fails at value's
    // location if it is not an object: "expected an object for camera 'overview', got an array".
    ObjectReader(const Value& value, std::string what);

    // Missing -> error at the object's location: "camera 'overview' has no 'eye'".
    const Value& required(std::string_view key);
    const Value* optional(std::string_view key);  // nullptr if absent

    // Every key not asked for by required/optional -> error at that key's location:
    // "unknown key 'fovy' in camera 'overview' (did you mean 'fovY'?); expected one of: eye, target, up, fovY"
    // (the keys asked for so far, in the order asked). Call after reading all keys.
    void finish() const;

    const Value& value() const { return *value_; }
    const std::string& what() const { return what_; }
    // Renames the object for later messages, e.g. once its "name" member has been read.
    void setWhat(std::string what) { what_ = std::move(what); }

private:
    void noteAsked(std::string_view key);

    const Value* value_;
    std::string what_;
    std::vector<std::string> asked_;
};

}  // namespace refray::json
