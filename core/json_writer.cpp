#include "core/json_writer.h"

#include <charconv>
#include <cmath>
#include <cstdio>

#include "core/error.h"

namespace refray::json {

std::string quoted(std::string_view text) {
    std::string out;
    out.reserve(text.size() + 2);
    out += '"';
    for (const char c : text) {
        switch (c) {
            case '"': out += "\\\""; break;
            case '\\': out += "\\\\"; break;
            case '\n': out += "\\n"; break;
            case '\r': out += "\\r"; break;
            case '\t': out += "\\t"; break;
            case '\b': out += "\\b"; break;
            case '\f': out += "\\f"; break;
            default:
                if (static_cast<unsigned char>(c) < 0x20) {
                    char escape[8];
                    std::snprintf(escape, sizeof escape, "\\u%04x", unsigned(static_cast<unsigned char>(c)));
                    out += escape;
                } else {
                    out += c;
                }
        }
    }
    out += '"';
    return out;
}

void Writer::newline(size_t depth) {
    out_ += '\n';
    out_.append(2 * depth, ' ');
}

void Writer::beforeValue() {
    REFRAY_ASSERT(!done_, "a JSON document holds one top-level value; the writer already has " << out_);
    if (levels_.empty()) return;
    Level& level = levels_.back();
    if (level.object) {
        REFRAY_ASSERT(level.keyPending, "a value inside a JSON object needs a key first; document so far: " << out_);
        level.keyPending = false;
        return;  // key() wrote the separator
    }
    if (!level.empty) out_ += level.inlineLayout ? ", " : ",";
    if (!level.inlineLayout) newline(levels_.size());
    level.empty = false;
}

Writer& Writer::key(std::string_view name) {
    REFRAY_ASSERT(!levels_.empty() && levels_.back().object && !levels_.back().keyPending,
                  "key '" << name << "' outside an object or after another key; document so far: " << out_);
    Level& level = levels_.back();
    if (!level.empty) out_ += level.inlineLayout ? ", " : ",";
    if (!level.inlineLayout) newline(levels_.size());
    level.empty = false;
    level.keyPending = true;
    out_ += quoted(name);
    out_ += ": ";
    return *this;
}

Writer& Writer::raw(std::string_view token) {
    beforeValue();
    out_ += token;
    if (levels_.empty()) {
        done_ = true;
        out_ += '\n';
    }
    return *this;
}

Writer& Writer::open(char bracket, bool object, Layout layout) {
    beforeValue();
    out_ += bracket;
    const bool parentInline = !levels_.empty() && levels_.back().inlineLayout;
    levels_.push_back({object, parentInline || layout == Layout::Inline, true, false});
    return *this;
}

Writer& Writer::close(char bracket, bool object) {
    REFRAY_ASSERT(!levels_.empty() && levels_.back().object == object && !levels_.back().keyPending,
                  "unbalanced '" << bracket << "' in the JSON writer; document so far: " << out_);
    const Level level = levels_.back();
    levels_.pop_back();
    if (!level.empty && !level.inlineLayout) newline(levels_.size());
    out_ += bracket;
    if (levels_.empty()) {
        done_ = true;
        out_ += '\n';
    }
    return *this;
}

Writer& Writer::beginObject(Layout layout) { return open('{', true, layout); }
Writer& Writer::endObject() { return close('}', true); }
Writer& Writer::beginArray(Layout layout) { return open('[', false, layout); }
Writer& Writer::endArray() { return close(']', false); }

Writer& Writer::value(std::string_view text) { return raw(quoted(text)); }
Writer& Writer::value(bool b) { return raw(b ? "true" : "false"); }
Writer& Writer::null() { return raw("null"); }

Writer& Writer::value(float number) {
    REFRAY_CHECK(std::isfinite(number), "JSON has no NaN or infinity; cannot write " << number);
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, number);
    return raw(std::string_view(text, size_t(end.ptr - text)));
}

Writer& Writer::value(double number) {
    REFRAY_CHECK(std::isfinite(number), "JSON has no NaN or infinity; cannot write " << number);
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, number);
    return raw(std::string_view(text, size_t(end.ptr - text)));
}

Writer& Writer::signedValue(int64_t number) { return raw(std::to_string(number)); }
Writer& Writer::unsignedValue(uint64_t number) { return raw(std::to_string(number)); }

const std::string& Writer::text() const {
    REFRAY_ASSERT(done_ && levels_.empty(), "the JSON document is incomplete: " << out_);
    return out_;
}

}  // namespace refray::json
