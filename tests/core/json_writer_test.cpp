// Tests core/json_writer.cpp: the exact text it writes, escaping, numbers, and that the reader
// (core/json.h) reads every document back.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/json.h"
#include "core/json_writer.h"

using namespace refray;
using namespace refray::json;

TEST(JsonWriter, WritesIndentedObjectsAndInlineArrays) {
    Writer w;
    w.beginObject();
    w.member("name", "slab").member("count", 3u).member("offset", int64_t(-2)).member("opaque", true);
    w.key("albedo").beginArray(Writer::Layout::Inline).value(1.0f).value(0.9f).value(0.7f).value(1.0f).endArray();
    w.key("records").beginArray();
    w.beginObject().member("index", 0).key("hitGroup").null().endObject();
    w.endArray();
    w.key("empty").beginObject().endObject();
    w.key("none").beginArray().endArray();
    w.endObject();
    EXPECT_EQ(w.text(),
              "{\n"
              "  \"name\": \"slab\",\n"
              "  \"count\": 3,\n"
              "  \"offset\": -2,\n"
              "  \"opaque\": true,\n"
              "  \"albedo\": [1, 0.9, 0.7, 1],\n"
              "  \"records\": [\n"
              "    {\n"
              "      \"index\": 0,\n"
              "      \"hitGroup\": null\n"
              "    }\n"
              "  ],\n"
              "  \"empty\": {},\n"
              "  \"none\": []\n"
              "}\n");
}

TEST(JsonWriter, InlineLayoutReachesNestedValues) {
    Writer w;
    w.beginArray(Writer::Layout::Inline).beginObject().member("a", 1).member("b", "x").endObject().value(2).endArray();
    EXPECT_EQ(w.text(), "[{\"a\": 1, \"b\": \"x\"}, 2]\n");
}

TEST(JsonWriter, EscapesStrings) {
    EXPECT_EQ(quoted("a\"b\\c\nd\te\x01"), "\"a\\\"b\\\\c\\nd\\te\\u0001\"");
    EXPECT_EQ(quoted("instance 'pacmanA' \xC3\xA9"), "\"instance 'pacmanA' \xC3\xA9\"");
}

TEST(JsonWriter, NumbersReadBackExactly) {
    Writer w;
    w.beginArray(Writer::Layout::Inline);
    w.value(0.3f).value(0.1).value(uint64_t(1) << 40).value(std::numeric_limits<int64_t>::min()).value(uint8_t(255));
    w.endArray();
    EXPECT_EQ(w.text(), "[0.3, 0.1, 1099511627776, -9223372036854775808, 255]\n");
    const Value v = parse(w.text(), "w.json");
    EXPECT_EQ(v.asArray()[0].asFloat(), 0.3f);
    EXPECT_EQ(v.asArray()[1].asNumber(), 0.1);
    EXPECT_EQ(v.asArray()[2].asInt(), int64_t(1) << 40);
}

TEST(JsonWriter, RoundTripsThroughTheReader) {
    Writer w;
    w.beginObject().member("text", "line\nbreak \"quoted\"").key("list").beginArray().value(1).value(false).null().endArray();
    w.endObject();
    const Value v = parse(w.text(), "w.json");
    EXPECT_EQ(v.find("text")->asString(), "line\nbreak \"quoted\"");
    ASSERT_EQ(v.find("list")->asArray().size(), 3u);
    EXPECT_TRUE(v.find("list")->asArray()[2].isNull());
}

TEST(JsonWriter, RefusesNonFiniteNumbers) {
    Writer w;
    w.beginArray();
    try {
        w.value(std::numeric_limits<double>::quiet_NaN());
        FAIL() << "NaN was written";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "JSON has no NaN or infinity; cannot write nan");
    }
    EXPECT_THROW(w.value(std::numeric_limits<float>::infinity()), Error);
}
