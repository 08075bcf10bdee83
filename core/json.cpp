#include "core/json.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <memory>
#include <system_error>
#include <unordered_map>

#include "core/error.h"
#include "core/file_input.h"
#include "core/strings.h"

namespace refray::json {

namespace {

constexpr uint32_t kMaxDepth = 256;

bool isDigit(char c) { return c >= '0' && c <= '9'; }
bool isLetter(char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
bool isWordChar(char c) { return isLetter(c) || isDigit(c) || c == '_'; }

int hexDigitValue(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

std::string hex(uint32_t value, int digits) {
    char buffer[16];
    std::snprintf(buffer, sizeof buffer, "%0*X", digits, unsigned(value));
    return buffer;
}

std::string lowercase(std::string_view s) {
    std::string out(s);
    for (char& c : out)
        if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
    return out;
}

// Length of the UTF-8 sequence that starts `s`, or 0 if it is not valid UTF-8
// (overlong forms, surrogates and code points past U+10FFFF are invalid).
size_t utf8SequenceLength(std::string_view s) {
    const auto lead = (unsigned char)s[0];
    if (lead < 0x80) return 1;
    size_t length = 0;
    uint32_t codePoint = 0, smallest = 0;
    if ((lead & 0xE0) == 0xC0) {
        length = 2, codePoint = lead & 0x1F, smallest = 0x80;
    } else if ((lead & 0xF0) == 0xE0) {
        length = 3, codePoint = lead & 0x0F, smallest = 0x800;
    } else if ((lead & 0xF8) == 0xF0) {
        length = 4, codePoint = lead & 0x07, smallest = 0x10000;
    } else {
        return 0;
    }
    if (s.size() < length) return 0;
    for (size_t i = 1; i < length; ++i) {
        const auto byte = (unsigned char)s[i];
        if ((byte & 0xC0) != 0x80) return 0;
        codePoint = (codePoint << 6) | (byte & 0x3F);
    }
    if (codePoint < smallest || codePoint > 0x10FFFF || (codePoint >= 0xD800 && codePoint <= 0xDFFF)) return 0;
    return length;
}

void appendUTF8(std::string& out, uint32_t codePoint) {
    if (codePoint < 0x80) {
        out += char(codePoint);
    } else if (codePoint < 0x800) {
        out += char(0xC0 | (codePoint >> 6));
        out += char(0x80 | (codePoint & 0x3F));
    } else if (codePoint < 0x10000) {
        out += char(0xE0 | (codePoint >> 12));
        out += char(0x80 | ((codePoint >> 6) & 0x3F));
        out += char(0x80 | (codePoint & 0x3F));
    } else {
        out += char(0xF0 | (codePoint >> 18));
        out += char(0x80 | ((codePoint >> 12) & 0x3F));
        out += char(0x80 | ((codePoint >> 6) & 0x3F));
        out += char(0x80 | (codePoint & 0x3F));
    }
}

// A JSON number's text as ±digits × 10^exponent, exactly: `digits` has no leading or
// trailing zeros and is empty for zero.
struct Decimal {
    bool negative = false;
    std::string digits;
    int64_t exponent = 0;
};

Decimal decompose(std::string_view text) {
    constexpr int64_t kExponentCap = 1'000'000'000'000;  // far past any double, far from overflow
    Decimal d;
    size_t i = 0;
    if (text[i] == '-') d.negative = true, ++i;
    int64_t fractionDigits = 0;
    bool inFraction = false;
    for (; i < text.size() && text[i] != 'e' && text[i] != 'E'; ++i) {
        if (text[i] == '.') {
            inFraction = true;
            continue;
        }
        if (inFraction) ++fractionDigits;
        if (d.digits.empty() && text[i] == '0') continue;
        d.digits += text[i];
    }
    int64_t exponent = 0;
    if (i < text.size()) {
        ++i;
        bool negativeExponent = false;
        if (text[i] == '+' || text[i] == '-') negativeExponent = text[i++] == '-';
        for (; i < text.size(); ++i) exponent = std::min(exponent * 10 + (text[i] - '0'), kExponentCap);
        if (negativeExponent) exponent = -exponent;
    }
    int64_t trailingZeros = 0;
    while (!d.digits.empty() && d.digits.back() == '0') d.digits.pop_back(), ++trailingZeros;
    d.exponent = exponent - fractionDigits + trailingZeros;
    return d;
}

enum class IntegerStatus { Ok, NotInteger, OutOfRange };

// The exact integer a number's text denotes ("25", "2.5e1" and "250e-1" all give 25).
IntegerStatus integerOf(std::string_view text, bool& negative, uint64_t& magnitude) {
    const Decimal d = decompose(text);
    negative = d.negative;
    magnitude = 0;
    if (d.digits.empty()) return IntegerStatus::Ok;
    if (d.exponent < 0) return IntegerStatus::NotInteger;
    if (int64_t(d.digits.size()) + d.exponent > 20) return IntegerStatus::OutOfRange;
    const std::string whole = d.digits + std::string(size_t(d.exponent), '0');
    const auto [end, ec] = std::from_chars(whole.data(), whole.data() + whole.size(), magnitude);
    return ec == std::errc() ? IntegerStatus::Ok : IntegerStatus::OutOfRange;
}

}  // namespace

std::string toString(const Location& location) {
    return location.file + ":" + std::to_string(location.line) + ":" + std::to_string(location.column);
}

// ---------------------------------------------------------------------------------------
// Parser

namespace detail {

class Parser {
public:
    Parser(std::string_view text, std::string file) : text_(text), file_(std::move(file)) {
        if (text_.substr(0, 3) == "\xEF\xBB\xBF") pos_ = lineStart_ = 3;
    }

    Value parseDocument() {
        Value root = parseValue(0);
        skipWhitespace();
        if (!atEnd()) unexpected("end of file after the top-level value");
        return root;
    }

private:
    bool atEnd() const { return pos_ >= text_.size(); }
    // '\0' past the end, so comparisons with any syntax character fail there.
    char peek(size_t ahead = 0) const { return pos_ + ahead < text_.size() ? text_[pos_ + ahead] : '\0'; }
    Location here() const { return {file_, line_, uint32_t(pos_ - lineStart_ + 1)}; }

    [[noreturn]] void fail(const Location& location, const std::string& message) const {
        throw Error(toString(location) + ": " + message);
    }

    // "expected X, got Y" about the text at the current position.
    [[noreturn]] void unexpected(const std::string& expected) const {
        if (atEnd()) fail(here(), "unexpected end of file, expected " + expected);
        fail(here(), "expected " + expected + ", got " + describe(pos_));
    }

    // What a person sees at `pos`, with a hint where JSON differs from what they may expect.
    std::string describe(size_t pos) const {
        const std::string_view rest = text_.substr(pos);
        if (rest.empty()) return "end of file";
        const char c = rest[0];
        const size_t wordStart = (c == '-' || c == '+') && rest.size() > 1 && isLetter(rest[1]) ? 1 : 0;
        if (isLetter(rest[wordStart])) {
            constexpr size_t kShown = 40;
            size_t end = wordStart;
            while (end < rest.size() && isWordChar(rest[end])) ++end;
            std::string word(rest.substr(0, std::min(end, kShown)));
            if (end > kShown) word += "...";
            const std::string bare = lowercase(rest.substr(wordStart, end - wordStart));
            const bool nonFinite = bare == "nan" || bare == "infinity" || bare == "inf";
            return quotedText(word, nonFinite ? " (JSON has no NaN or Infinity)" : "");
        }
        if (c == '/' && rest.size() > 1 && (rest[1] == '/' || rest[1] == '*'))
            return quotedText(rest.substr(0, 2), " (JSON has no comments)");
        if (c == '\'') return "a single quote (JSON strings use double quotes)";
        if (c == '+') return "'+' (JSON numbers have no '+' sign)";
        if (c == '\n' || c == '\r') return "a line break";
        if (c == '\t') return "a tab";
        if (c == ' ') return "a space";
        const auto byte = (unsigned char)c;
        if (byte < 0x20 || byte == 0x7F) return "control character 0x" + hex(byte, 2);
        if (byte >= 0x80) {
            const size_t length = utf8SequenceLength(rest);
            if (length == 0) return "byte 0x" + hex(byte, 2) + " (not UTF-8)";
            return quotedText(rest.substr(0, length));
        }
        return quotedText(std::string_view(&c, 1));
    }

    // 'text' followed by `suffix`, built by appending (GCC 12 warns, wrongly, on "'" + std::string(...)).
    static std::string quotedText(std::string_view text, std::string_view suffix = "") {
        std::string out;
        out.reserve(text.size() + suffix.size() + 2);
        out += '\'';
        out.append(text);
        out += '\'';
        out.append(suffix);
        return out;
    }

    void newLine() {
        ++line_;
        lineStart_ = pos_;
    }

    void skipWhitespace() {
        while (!atEnd()) {
            const char c = text_[pos_];
            if (c == ' ' || c == '\t') {
                ++pos_;
            } else if (c == '\n') {
                ++pos_;
                newLine();
            } else if (c == '\r') {  // "\r\n" is one line break, counted at the '\n'
                ++pos_;
                if (peek() != '\n') newLine();
            } else {
                break;
            }
        }
    }

    void skipDigits() {
        while (isDigit(peek())) ++pos_;
    }

    Value start(Value::Kind kind) const {
        Value value;
        value.kind_ = kind;
        value.location_ = here();
        return value;
    }

    void checkDepth(uint32_t depth, const Location& location) const {
        if (depth > kMaxDepth)
            fail(location, "arrays and objects nested deeper than " + std::to_string(kMaxDepth) + " levels");
    }

    // `depth` counts the arrays and objects around the value.
    Value parseValue(uint32_t depth) {
        skipWhitespace();
        if (atEnd()) unexpected("a value");
        const char c = text_[pos_];
        if (c == '{') return parseObject(depth + 1);
        if (c == '[') return parseArray(depth + 1);
        if (c == '"') {
            Value value = start(Value::Kind::String);
            value.text_ = parseString();
            return value;
        }
        if (isDigit(c) || (c == '-' && !isLetter(peek(1)))) return parseNumber();
        if (isLetter(c)) return parseLiteral();
        unexpected("a value");
    }

    Value parseLiteral() {
        size_t end = pos_;
        while (end < text_.size() && isWordChar(text_[end])) ++end;
        const std::string_view word = text_.substr(pos_, end - pos_);
        Value value;
        if (word == "true" || word == "false") {
            value = start(Value::Kind::Bool);
            value.bool_ = word == "true";
        } else if (word == "null") {
            value = start(Value::Kind::Null);
        } else {
            unexpected("a value");
        }
        pos_ = end;
        return value;
    }

    Value parseNumber() {
        Value value = start(Value::Kind::Number);
        const size_t begin = pos_;
        if (peek() == '-') ++pos_;
        if (peek() == '0') {
            ++pos_;
            if (isDigit(peek())) {
                skipDigits();
                fail(value.location_, "expected a number without leading zeros, got '" +
                                          std::string(text_.substr(begin, pos_ - begin)) + "'");
            }
        } else if (isDigit(peek())) {
            skipDigits();
        } else {
            unexpected("a digit after '-'");
        }
        if (peek() == '.') {
            ++pos_;
            if (!isDigit(peek())) unexpected("a digit after '.'");
            skipDigits();
        }
        if (peek() == 'e' || peek() == 'E') {
            ++pos_;
            if (peek() == '+' || peek() == '-') ++pos_;
            if (!isDigit(peek())) unexpected("a digit in the exponent");
            skipDigits();
        }
        value.text_ = std::string(text_.substr(begin, pos_ - begin));

        const char* first = value.text_.data();
        const char* last = first + value.text_.size();
        const auto [end, ec] = std::from_chars(first, last, value.number_);
        if (ec == std::errc::result_out_of_range) {
            // Too large is an error; too small for even a subnormal double is zero.
            const Decimal d = decompose(value.text_);
            if (int64_t(d.digits.size()) + d.exponent > 0)
                fail(value.location_, value.text_ + " does not fit in a 64-bit double");
            value.number_ = d.negative ? -0.0 : 0.0;
        } else {
            REFRAY_ASSERT(ec == std::errc() && end == last, "from_chars rejected '" << value.text_ << "'");
        }
        return value;
    }

    // The current position is the opening quote.
    std::string parseString() {
        const Location opening = here();
        ++pos_;
        std::string out;
        while (true) {
            if (atEnd()) fail(opening, "unterminated string (end of file before the closing '\"')");
            const char c = text_[pos_];
            const auto byte = (unsigned char)c;
            if (c == '"') {
                ++pos_;
                return out;
            }
            if (c == '\\') {
                parseEscape(out, opening);
            } else if (c == '\n' || c == '\r') {
                fail(opening, "unterminated string (line break before the closing '\"'; write a line break "
                              "in a string as \\n)");
            } else if (byte < 0x20) {
                fail(here(), "expected a string character, got " + describe(pos_) + " (write it as \\u" +
                                 hex(byte, 4) + ")");
            } else if (byte < 0x80) {
                size_t end = pos_ + 1;
                while (end < text_.size() && (unsigned char)text_[end] >= 0x20 && (unsigned char)text_[end] < 0x80 &&
                       text_[end] != '"' && text_[end] != '\\')
                    ++end;
                out.append(text_.substr(pos_, end - pos_));
                pos_ = end;
            } else {
                const size_t length = utf8SequenceLength(text_.substr(pos_));
                if (length == 0) fail(here(), "expected UTF-8 text in a string, got byte 0x" + hex(byte, 2));
                out.append(text_.substr(pos_, length));
                pos_ += length;
            }
        }
    }

    // The current position is the backslash.
    void parseEscape(std::string& out, const Location& opening) {
        const Location backslash = here();
        ++pos_;
        if (atEnd()) fail(opening, "unterminated string (end of file before the closing '\"')");
        const char e = text_[pos_];
        char simple = 0;
        switch (e) {
            case '"': simple = '"'; break;
            case '\\': simple = '\\'; break;
            case '/': simple = '/'; break;
            case 'b': simple = '\b'; break;
            case 'f': simple = '\f'; break;
            case 'n': simple = '\n'; break;
            case 'r': simple = '\r'; break;
            case 't': simple = '\t'; break;
            case 'u': break;
            default: unexpected("an escape (\\\" \\\\ \\/ \\b \\f \\n \\r \\t or \\uXXXX) after '\\'");
        }
        ++pos_;
        if (simple != 0) {
            out += simple;
            return;
        }
        const uint32_t unit = parseHex4();
        if (unit >= 0xD800 && unit <= 0xDBFF) {
            if (peek() == '\\' && peek(1) == 'u') {
                pos_ += 2;
                const uint32_t low = parseHex4();
                if (low >= 0xDC00 && low <= 0xDFFF) {
                    appendUTF8(out, 0x10000 + ((unit - 0xD800) << 10) + (low - 0xDC00));
                    return;
                }
            }
            fail(backslash, "unpaired surrogate \\u" + hex(unit, 4) +
                                ": expected a low surrogate \\uDC00 to \\uDFFF right after it");
        }
        if (unit >= 0xDC00 && unit <= 0xDFFF)
            fail(backslash, "unpaired surrogate \\u" + hex(unit, 4) +
                                ": a low surrogate must follow a high surrogate \\uD800 to \\uDBFF");
        appendUTF8(out, unit);
    }

    uint32_t parseHex4() {
        uint32_t unit = 0;
        for (int i = 0; i < 4; ++i) {
            const int digit = hexDigitValue(peek());
            if (digit < 0) unexpected("4 hex digits after '\\u'");
            unit = unit * 16 + uint32_t(digit);
            ++pos_;
        }
        return unit;
    }

    Value parseArray(uint32_t depth) {
        Value array = start(Value::Kind::Array);
        checkDepth(depth, array.location_);
        ++pos_;
        skipWhitespace();
        if (peek() == ']') {
            ++pos_;
            return array;
        }
        while (true) {
            array.array_.push_back(parseValue(depth));
            skipWhitespace();
            if (peek() == ']') {
                ++pos_;
                return array;
            }
            if (peek() != ',') unexpected("',' or ']' after an array element");
            const Location comma = here();
            ++pos_;
            skipWhitespace();
            if (peek() == ']') fail(comma, "trailing comma before ']'");
        }
    }

    Value parseObject(uint32_t depth) {
        Value object = start(Value::Kind::Object);
        checkDepth(depth, object.location_);
        ++pos_;
        skipWhitespace();
        if (peek() == '}') {
            ++pos_;
            return object;
        }
        std::unordered_map<std::string, size_t> memberOfKey;
        bool afterComma = false;
        while (true) {
            if (peek() != '"') unexpected(afterComma ? "a string key after ','" : "a string key or '}'");
            Member member;
            member.keyLocation = here();
            member.key = parseString();
            const auto [it, inserted] = memberOfKey.emplace(member.key, object.object_.size());
            if (!inserted)
                fail(member.keyLocation, "duplicate key '" + member.key + "'; it was first defined at " +
                                             toString(object.object_[it->second].keyLocation));
            skipWhitespace();
            if (peek() != ':') unexpected("':' after an object key");
            ++pos_;
            member.value = parseValue(depth);
            object.object_.push_back(std::move(member));
            skipWhitespace();
            if (peek() == '}') {
                ++pos_;
                return object;
            }
            if (peek() != ',') unexpected("',' or '}' after an object member");
            const Location comma = here();
            ++pos_;
            skipWhitespace();
            if (peek() == '}') fail(comma, "trailing comma before '}'");
            afterComma = true;
        }
    }

    std::string_view text_;
    std::string file_;
    size_t pos_ = 0;
    uint32_t line_ = 1;
    size_t lineStart_ = 0;  // offset of the first byte of the current line
};

}  // namespace detail

Value parse(std::string_view text, std::string file) { return detail::Parser(text, std::move(file)).parseDocument(); }

Value parseFile(const std::filesystem::path& path) {
    return parse(readInputFile(path.string(), "JSON file"), path.string());
}

// ---------------------------------------------------------------------------------------
// Value

Value::Value() = default;
Value::Value(const Value& other) = default;
Value::Value(Value&& other) noexcept = default;
Value& Value::operator=(const Value& other) = default;
Value& Value::operator=(Value&& other) noexcept = default;
Value::~Value() = default;

std::string_view Value::kindName() const {
    switch (kind_) {
        case Kind::Null: return "null";
        case Kind::Bool: return "a boolean";
        case Kind::Number: return "a number";
        case Kind::String: return "a string";
        case Kind::Array: return "an array";
        case Kind::Object: return "an object";
    }
    return "an unknown kind";
}

void Value::fail(const std::string& message) const { throw Error(toString(location_) + ": " + message); }

void Value::failKind(std::string_view expected) const {
    fail("expected " + std::string(expected) + ", got " + std::string(kindName()));
}

bool Value::asBool() const {
    if (!isBool()) failKind("a boolean");
    return bool_;
}

double Value::asNumber() const {
    if (!isNumber()) failKind("a number");
    return number_;
}

float Value::asFloat() const {
    const double number = asNumber();
    // Halfway between FLT_MAX and 2^128: from here on, rounding to float gives infinity.
    constexpr double kFloatOverflow = 0x1.ffffffp127;
    if (std::fabs(number) >= kFloatOverflow) fail(text_ + " does not fit in a 32-bit float");
    return float(number);
}

int64_t Value::asInt() const {
    if (!isNumber()) failKind("a number");
    bool negative = false;
    uint64_t magnitude = 0;
    const IntegerStatus status = integerOf(text_, negative, magnitude);
    if (status == IntegerStatus::NotInteger) fail("expected an integer, got " + text_);
    constexpr uint64_t kMostNegative = uint64_t(1) << 63;
    if (status == IntegerStatus::OutOfRange || magnitude > (negative ? kMostNegative : kMostNegative - 1))
        fail(text_ + " does not fit in a 64-bit signed integer");
    if (negative) return magnitude == kMostNegative ? INT64_MIN : -int64_t(magnitude);
    return int64_t(magnitude);
}

uint32_t Value::asUint32() const {
    if (!isNumber()) failKind("a number");
    bool negative = false;
    uint64_t magnitude = 0;
    const IntegerStatus status = integerOf(text_, negative, magnitude);
    if (status == IntegerStatus::NotInteger) fail("expected an integer, got " + text_);
    if (status == IntegerStatus::OutOfRange || (negative && magnitude != 0) || magnitude > UINT32_MAX)
        fail(text_ + " does not fit in a 32-bit unsigned integer (0 to 4294967295)");
    return uint32_t(magnitude);
}

const std::string& Value::asString() const {
    if (!isString()) failKind("a string");
    return text_;
}

const std::vector<Value>& Value::asArray() const {
    if (!isArray()) failKind("an array");
    return array_;
}

const std::vector<Member>& Value::asObject() const {
    if (!isObject()) failKind("an object");
    return object_;
}

const Value* Value::find(std::string_view key) const {
    for (const Member& member : asObject())
        if (member.key == key) return &member.value;
    return nullptr;
}

const std::string& Value::numberText() const {
    if (!isNumber()) failKind("a number");
    return text_;
}

// ---------------------------------------------------------------------------------------
// ObjectReader

ObjectReader::ObjectReader(const Value& value, std::string what) : value_(&value), what_(std::move(what)) {
    if (!value.isObject()) value.fail("expected an object for " + what_ + ", got " + std::string(value.kindName()));
}

void ObjectReader::noteAsked(std::string_view key) {
    if (std::find(asked_.begin(), asked_.end(), key) == asked_.end()) asked_.emplace_back(key);
}

const Value& ObjectReader::required(std::string_view key) {
    noteAsked(key);
    if (const Value* found = value_->find(key)) return *found;
    // A present key that is close to the missing one is probably its misspelling: point at it.
    std::vector<std::string> present;
    const Member* misspelt = nullptr;
    for (const Member& member : value_->asObject()) present.push_back(member.key);
    if (const std::optional<std::string> close = closestMatch(key, present))
        for (const Member& member : value_->asObject())
            if (member.key == *close) misspelt = &member;
    if (misspelt)
        throw Error(toString(misspelt->keyLocation) + ": " + what_ + " has no '" + std::string(key) + "'; is '" +
                    misspelt->key + "' a misspelling of it?");
    value_->fail(what_ + " has no '" + std::string(key) + "'");
}

const Value* ObjectReader::optional(std::string_view key) {
    noteAsked(key);
    return value_->find(key);
}

void ObjectReader::finish() const {
    for (const Member& member : value_->asObject()) {
        if (std::find(asked_.begin(), asked_.end(), member.key) != asked_.end()) continue;
        std::string message = "unknown key '" + member.key + "' in " + what_ + didYouMean(member.key, asked_);
        if (asked_.empty()) {
            message += "; it takes no keys";
        } else {
            message += "; expected one of: ";
            for (size_t i = 0; i < asked_.size(); ++i) message += (i ? ", " : "") + asked_[i];
        }
        throw Error(toString(member.keyLocation) + ": " + message);
    }
}

// ---- JSON Patch ------------------------------------------------------------------------------------

namespace {

// RFC 6901: "/a/b~1c" -> {"a", "b/c"}.
std::vector<std::string> pointerTokens(const Value& path) {
    const std::string& text = path.asString();
    if (text.empty()) path.fail("a patch path must name a member or element, not the whole document");
    if (text[0] != '/') path.fail("a JSON Pointer starts with '/', got '" + text + "'");
    std::vector<std::string> tokens;
    std::string token;
    for (size_t i = 1; i <= text.size(); ++i) {
        if (i == text.size() || text[i] == '/') {
            tokens.push_back(token);
            token.clear();
        } else if (text[i] == '~') {
            if (i + 1 < text.size() && (text[i + 1] == '0' || text[i + 1] == '1')) {
                token += text[i + 1] == '0' ? '~' : '/';
                ++i;
            } else {
                path.fail("'~' in a JSON Pointer must be followed by 0 or 1: '" + text + "'");
            }
        } else {
            token += text[i];
        }
    }
    return tokens;
}

// An array index token: digits without leading zeros, below `limit` (inclusive when `allowEnd`).
size_t arrayIndex(const Value& path, const std::string& token, size_t size, bool allowEnd) {
    const bool digits = !token.empty() && token.size() <= 9 &&
                        std::all_of(token.begin(), token.end(), [](char c) { return c >= '0' && c <= '9'; }) &&
                        (token.size() == 1 || token[0] != '0');
    if (!digits) path.fail("'" + token + "' in path '" + path.asString() + "' is not an array index");
    const size_t index = std::stoul(token);
    if (index > size || (index == size && !allowEnd))
        path.fail("path '" + path.asString() + "': index " + token + " is past the end of an array of " +
                  std::to_string(size) + " elements");
    return index;
}

}  // namespace

void applyPatch(Value& document, const Value& patch) {
    for (const Value& operation : patch.asArray()) {
        ObjectReader reader(operation, "a patch operation");
        const Value& opValue = reader.required("op");
        const std::string& op = opValue.asString();
        if (op != "replace" && op != "add" && op != "remove")
            opValue.fail("unknown patch op '" + op + "'" + didYouMean(op, {"replace", "add", "remove"}) +
                         "; expected replace, add or remove");
        const Value& path = reader.required("path");
        const Value* value = op == "remove" ? nullptr : &reader.required("value");
        reader.finish();

        const std::vector<std::string> tokens = pointerTokens(path);
        Value* parent = &document;
        for (size_t i = 0; i + 1 < tokens.size(); ++i) {
            if (parent->kind_ == Value::Kind::Object) {
                auto it = std::find_if(parent->object_.begin(), parent->object_.end(),
                                       [&](const Member& m) { return m.key == tokens[i]; });
                if (it == parent->object_.end())
                    path.fail("path '" + path.asString() + "': no member '" + tokens[i] + "'");
                parent = &it->value;
            } else if (parent->kind_ == Value::Kind::Array) {
                parent = &parent->array_[arrayIndex(path, tokens[i], parent->array_.size(), false)];
            } else {
                path.fail("path '" + path.asString() + "': '" + tokens[i] + "' is inside " +
                          std::string(parent->kindName()));
            }
        }
        const std::string& last = tokens.back();
        if (parent->kind_ == Value::Kind::Object) {
            auto it = std::find_if(parent->object_.begin(), parent->object_.end(), [&](const Member& m) { return m.key == last; });
            if (op != "add" && it == parent->object_.end())
                path.fail("path '" + path.asString() + "': no member '" + last + "' to " + op);
            if (op == "remove") {
                parent->object_.erase(it);
            } else if (it != parent->object_.end()) {
                it->value = *value;
            } else {
                parent->object_.push_back(Member{last, path.location(), *value});
            }
        } else if (parent->kind_ == Value::Kind::Array) {
            std::vector<Value>& array = parent->array_;
            if (op == "add") {
                const size_t at = last == "-" ? array.size() : arrayIndex(path, last, array.size(), true);
                array.insert(array.begin() + std::ptrdiff_t(at), *value);
            } else {
                const size_t at = arrayIndex(path, last, array.size(), false);
                if (op == "remove") array.erase(array.begin() + std::ptrdiff_t(at));
                else array[at] = *value;
            }
        } else {
            path.fail("path '" + path.asString() + "': '" + last + "' is inside " + std::string(parent->kindName()));
        }
    }
}

}  // namespace refray::json
