#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <fstream>

#include "core/error.h"
#include "core/json.h"
#include "tests/error_of.h"

using namespace refray;
using namespace refray::json;

namespace {

// The message parse() throws for `text`, or "no error".
std::string parseError(std::string_view text) {
    try {
        parse(text, "t.json");
    } catch (const Error& e) {
        return e.what();
    }
    return "no error";
}

using refray::testing::errorOf;

std::string at(const Location& location) { return toString(location); }

}  // namespace

// ---------------------------------------------------------------------------------------
// Values

TEST(Json, ParsesEveryKind) {
    const Value v = parse(R"({"n": null, "t": true, "f": false, "num": -12.5e1, "s": "hi",
                            "a": [1, [], {}], "o": {"k": "v"}})",
                          "t.json");
    ASSERT_TRUE(v.isObject());
    EXPECT_EQ(v.kindName(), "an object");
    ASSERT_EQ(v.asObject().size(), 7u);
    EXPECT_EQ(v.asObject()[0].key, "n");
    EXPECT_EQ(v.asObject()[6].key, "o");

    EXPECT_TRUE(v.find("n")->isNull());
    EXPECT_EQ(v.find("n")->kindName(), "null");
    EXPECT_TRUE(v.find("t")->asBool());
    EXPECT_FALSE(v.find("f")->asBool());
    EXPECT_EQ(v.find("f")->kindName(), "a boolean");
    EXPECT_EQ(v.find("num")->asNumber(), -125.0);
    EXPECT_EQ(v.find("num")->kindName(), "a number");
    EXPECT_EQ(v.find("s")->asString(), "hi");
    EXPECT_EQ(v.find("s")->kindName(), "a string");

    const auto& a = v.find("a")->asArray();
    EXPECT_EQ(v.find("a")->kindName(), "an array");
    ASSERT_EQ(a.size(), 3u);
    EXPECT_EQ(a[0].asInt(), 1);
    EXPECT_TRUE(a[1].isArray());
    EXPECT_TRUE(a[1].asArray().empty());
    EXPECT_TRUE(a[2].isObject());
    EXPECT_TRUE(a[2].asObject().empty());
    EXPECT_EQ(v.find("o")->find("k")->asString(), "v");
    EXPECT_EQ(v.find("absent"), nullptr);
    EXPECT_EQ(v.find("o")->kind(), Value::Kind::Object);
}

TEST(Json, TopLevelScalars) {
    EXPECT_EQ(parse(" 42 ", "t.json").asInt(), 42);
    EXPECT_TRUE(parse("null", "t.json").isNull());
    EXPECT_EQ(parse("\"x\"", "t.json").asString(), "x");
    EXPECT_EQ(parse("-0.5", "t.json").asNumber(), -0.5);
}

TEST(Json, ValuesCopyAndMove) {
    Value copy;
    EXPECT_TRUE(copy.isNull());
    {
        const Value original = parse(R"({"a": [1, {"b": "c"}]})", "t.json");
        copy = original;
    }
    EXPECT_EQ(copy.find("a")->asArray()[1].find("b")->asString(), "c");
    const Value moved = std::move(copy);
    EXPECT_EQ(moved.find("a")->asArray()[0].asInt(), 1);
    EXPECT_EQ(at(moved.find("a")->asArray()[1].location()), "t.json:1:11");
}

TEST(Json, StringEscapes) {
    const Value v = parse(R"("\"\\\/\b\f\n\r\t|\u0041\u00e9\u20AC\uD83D\uDE00")", "t.json");
    EXPECT_EQ(v.asString(), "\"\\/\b\f\n\r\t|A\xC3\xA9\xE2\x82\xAC\xF0\x9F\x98\x80");
    EXPECT_EQ(parse(R"("a\u0000b")", "t.json").asString(), std::string("a\0b", 3));
    // Raw UTF-8 passes through unchanged; DEL is not a control character in JSON.
    EXPECT_EQ(parse("\"\xC3\xA9\xF0\x9F\x98\x80\x7F\"", "t.json").asString(), "\xC3\xA9\xF0\x9F\x98\x80\x7F");
}

TEST(Json, NumbersKeepTheirSourceText) {
    const Value v = parse("[15.8429795, -0.0, 1E+2, 0, 1e-400, -1e-400, 4e-320]", "t.json");
    const auto& a = v.asArray();
    EXPECT_EQ(a[0].numberText(), "15.8429795");
    EXPECT_EQ(a[0].asNumber(), 15.8429795);
    EXPECT_EQ(a[1].numberText(), "-0.0");
    EXPECT_TRUE(std::signbit(a[1].asNumber()));
    EXPECT_EQ(a[2].numberText(), "1E+2");
    EXPECT_EQ(a[2].asNumber(), 100.0);
    EXPECT_EQ(a[3].numberText(), "0");
    // Below the smallest subnormal: zero with its sign; subnormals are kept.
    EXPECT_EQ(a[4].asNumber(), 0.0);
    EXPECT_FALSE(std::signbit(a[4].asNumber()));
    EXPECT_TRUE(std::signbit(a[5].asNumber()));
    EXPECT_EQ(a[6].asNumber(), 4e-320);
    EXPECT_EQ(errorOf([] { parse("\"x\"", "t.json").numberText(); }), "t.json:1:1: expected a number, got a string");
}

// ---------------------------------------------------------------------------------------
// Locations

TEST(Json, LocationsOfValuesAndKeys) {
    const Value v = parse("{\n"
                          "  \"camera\": {\n"
                          "    \"eye\": [1, 2.5, -3],\n"
                          "    \"fovY\": 45\n"
                          "  },\n"
                          "  \"name\": \"x\"\n"
                          "}\n",
                          "scene.json");
    EXPECT_EQ(at(v.location()), "scene.json:1:1");
    const Member& camera = v.asObject()[0];
    EXPECT_EQ(at(camera.keyLocation), "scene.json:2:3");
    EXPECT_EQ(at(camera.value.location()), "scene.json:2:13");
    const Member& eye = camera.value.asObject()[0];
    EXPECT_EQ(at(eye.keyLocation), "scene.json:3:5");
    EXPECT_EQ(at(eye.value.location()), "scene.json:3:12");
    EXPECT_EQ(at(eye.value.asArray()[0].location()), "scene.json:3:13");
    EXPECT_EQ(at(eye.value.asArray()[1].location()), "scene.json:3:16");
    EXPECT_EQ(at(eye.value.asArray()[2].location()), "scene.json:3:21");
    const Member& fovY = camera.value.asObject()[1];
    EXPECT_EQ(at(fovY.keyLocation), "scene.json:4:5");
    EXPECT_EQ(at(fovY.value.location()), "scene.json:4:13");
    const Member& name = v.asObject()[1];
    EXPECT_EQ(at(name.keyLocation), "scene.json:6:3");
    EXPECT_EQ(at(name.value.location()), "scene.json:6:11");
    EXPECT_EQ(name.value.location().file, "scene.json");
    EXPECT_EQ(name.value.location().line, 6u);
    EXPECT_EQ(name.value.location().column, 11u);
}

TEST(Json, LineBreaksAndByteOrderMark) {
    // "\r\n" is one line break, a lone '\r' is one too; columns count bytes.
    const Value v = parse("[1,\r\n 2,\r3, \"\xC3\xA9\", 4]", "t.json");
    EXPECT_EQ(at(v.asArray()[1].location()), "t.json:2:2");
    EXPECT_EQ(at(v.asArray()[2].location()), "t.json:3:1");
    EXPECT_EQ(at(v.asArray()[4].location()), "t.json:3:10");
    // A UTF-8 byte order mark is skipped and not counted.
    EXPECT_EQ(at(parse("\xEF\xBB\xBF{}", "t.json").location()), "t.json:1:1");
}

TEST(Json, ValueFailReportsItsLocation) {
    const Value v = parse("{\n  \"size\": [1, 2]\n}", "t.json");
    EXPECT_EQ(errorOf([&] { v.find("size")->asArray()[1].fail("must be even"); }), "t.json:2:15: must be even");
}

// ---------------------------------------------------------------------------------------
// Syntax errors

TEST(Json, ErrorsInObjects) {
    EXPECT_EQ(parseError(R"({"a": 1 "b": 2})"), "t.json:1:9: expected ',' or '}' after an object member, got '\"'");
    EXPECT_EQ(parseError(R"({"a" 1})"), "t.json:1:6: expected ':' after an object key, got '1'");
    EXPECT_EQ(parseError(R"({"a")"), "t.json:1:5: unexpected end of file, expected ':' after an object key");
    EXPECT_EQ(parseError(R"({a: 1})"), "t.json:1:2: expected a string key or '}', got 'a'");
    EXPECT_EQ(parseError(R"({"a": 1, b})"), "t.json:1:10: expected a string key after ',', got 'b'");
    EXPECT_EQ(parseError("{\"a\": 1,\n}"), "t.json:1:8: trailing comma before '}'");
    EXPECT_EQ(parseError(R"({"a": })"), "t.json:1:7: expected a value, got '}'");
    EXPECT_EQ(parseError(R"({"a": 1)"), "t.json:1:8: unexpected end of file, expected ',' or '}' after an object member");
}

TEST(Json, ErrorsInArrays) {
    EXPECT_EQ(parseError("[1 2]"), "t.json:1:4: expected ',' or ']' after an array element, got '2'");
    EXPECT_EQ(parseError("[1, 2,]"), "t.json:1:6: trailing comma before ']'");
    EXPECT_EQ(parseError("[1,"), "t.json:1:4: unexpected end of file, expected a value");
    EXPECT_EQ(parseError("[,]"), "t.json:1:2: expected a value, got ','");
    EXPECT_EQ(parseError("[1}"), "t.json:1:3: expected ',' or ']' after an array element, got '}'");
}

TEST(Json, ErrorsAtTopLevel) {
    EXPECT_EQ(parseError(""), "t.json:1:1: unexpected end of file, expected a value");
    EXPECT_EQ(parseError("  \n  "), "t.json:2:3: unexpected end of file, expected a value");
    EXPECT_EQ(parseError("[1] 2"), "t.json:1:5: expected end of file after the top-level value, got '2'");
    EXPECT_EQ(parseError("{}\n}"), "t.json:2:1: expected end of file after the top-level value, got '}'");
    EXPECT_EQ(parseError("tru"), "t.json:1:1: expected a value, got 'tru'");
    EXPECT_EQ(parseError("nulls"), "t.json:1:1: expected a value, got 'nulls'");
    EXPECT_EQ(parseError("// note\n1"), "t.json:1:1: expected a value, got '//' (JSON has no comments)");
    EXPECT_EQ(parseError("[1 /* note */]"), "t.json:1:4: expected ',' or ']' after an array element, got '/*' (JSON has no comments)");
    EXPECT_EQ(parseError("['a']"), "t.json:1:2: expected a value, got a single quote (JSON strings use double quotes)");
    EXPECT_EQ(parseError("[\x01]"), "t.json:1:2: expected a value, got control character 0x01");
    EXPECT_EQ(parseError("[\xFF]"), "t.json:1:2: expected a value, got byte 0xFF (not UTF-8)");
}

TEST(Json, ErrorsInStrings) {
    EXPECT_EQ(parseError("\"abc"), "t.json:1:1: unterminated string (end of file before the closing '\"')");
    EXPECT_EQ(parseError("\"abc\\"), "t.json:1:1: unterminated string (end of file before the closing '\"')");
    EXPECT_EQ(parseError("[\n \"ab\ncd\"]"),
              "t.json:2:2: unterminated string (line break before the closing '\"'; write a line break in a string "
              "as \\n)");
    EXPECT_EQ(parseError(R"("\x")"),
              "t.json:1:3: expected an escape (\\\" \\\\ \\/ \\b \\f \\n \\r \\t or \\uXXXX) after '\\', got 'x'");
    EXPECT_EQ(parseError(R"("\u12G4")"), "t.json:1:6: expected 4 hex digits after '\\u', got 'G4'");
    EXPECT_EQ(parseError(R"("\u12)"), "t.json:1:6: unexpected end of file, expected 4 hex digits after '\\u'");
    EXPECT_EQ(parseError("\"a\tb\""), "t.json:1:3: expected a string character, got a tab (write it as \\u0009)");
    EXPECT_EQ(parseError("\"a\xFF\""), "t.json:1:3: expected UTF-8 text in a string, got byte 0xFF");
    EXPECT_EQ(parseError("\"\xC0\xAF\""), "t.json:1:2: expected UTF-8 text in a string, got byte 0xC0");  // overlong '/'
    EXPECT_EQ(parseError("\"\xED\xA0\x80\""), "t.json:1:2: expected UTF-8 text in a string, got byte 0xED");  // surrogate
}

TEST(Json, UnpairedSurrogatesAreErrors) {
    EXPECT_EQ(parseError(R"(["\uD800"])"),
              "t.json:1:3: unpaired surrogate \\uD800: expected a low surrogate \\uDC00 to \\uDFFF right after it");
    EXPECT_EQ(parseError(R"(["\uD800\u0041"])"),
              "t.json:1:3: unpaired surrogate \\uD800: expected a low surrogate \\uDC00 to \\uDFFF right after it");
    EXPECT_EQ(parseError(R"(["x\udc00"])"),
              "t.json:1:4: unpaired surrogate \\uDC00: a low surrogate must follow a high surrogate \\uD800 to \\uDBFF");
}

TEST(Json, ErrorsInNumbers) {
    EXPECT_EQ(parseError("[01]"), "t.json:1:2: expected a number without leading zeros, got '01'");
    EXPECT_EQ(parseError("-007"), "t.json:1:1: expected a number without leading zeros, got '-007'");
    EXPECT_EQ(parseError("+1"), "t.json:1:1: expected a value, got '+' (JSON numbers have no '+' sign)");
    EXPECT_EQ(parseError(".5"), "t.json:1:1: expected a value, got '.'");
    EXPECT_EQ(parseError("1."), "t.json:1:3: unexpected end of file, expected a digit after '.'");
    EXPECT_EQ(parseError("[1.e5]"), "t.json:1:4: expected a digit after '.', got 'e5'");
    EXPECT_EQ(parseError("[1e]"), "t.json:1:4: expected a digit in the exponent, got ']'");
    EXPECT_EQ(parseError("[1e+]"), "t.json:1:5: expected a digit in the exponent, got ']'");
    EXPECT_EQ(parseError("[-]"), "t.json:1:3: expected a digit after '-', got ']'");
    EXPECT_EQ(parseError("[0x10]"), "t.json:1:3: expected ',' or ']' after an array element, got 'x10'");
    EXPECT_EQ(parseError("[1e999]"), "t.json:1:2: 1e999 does not fit in a 64-bit double");
    EXPECT_EQ(parseError("[-1e999]"), "t.json:1:2: -1e999 does not fit in a 64-bit double");
}

TEST(Json, NaNAndInfinityAreErrors) {
    EXPECT_EQ(parseError("[NaN]"), "t.json:1:2: expected a value, got 'NaN' (JSON has no NaN or Infinity)");
    EXPECT_EQ(parseError("Infinity"), "t.json:1:1: expected a value, got 'Infinity' (JSON has no NaN or Infinity)");
    EXPECT_EQ(parseError("-Infinity"), "t.json:1:1: expected a value, got '-Infinity' (JSON has no NaN or Infinity)");
    EXPECT_EQ(parseError("{\"x\": nan}"), "t.json:1:7: expected a value, got 'nan' (JSON has no NaN or Infinity)");
    EXPECT_EQ(parseError("[-inf]"), "t.json:1:2: expected a value, got '-inf' (JSON has no NaN or Infinity)");
}

TEST(Json, DuplicateKeyNamesBothLocations) {
    EXPECT_EQ(parseError("{\"a\": 1,\n \"b\": 2,\n \"a\": 3}"),
              "t.json:3:2: duplicate key 'a'; it was first defined at t.json:1:2");
    // The same key in different objects is fine.
    EXPECT_NO_THROW(parse(R"({"a": {"a": 1}, "b": {"a": 2}})", "t.json"));
}

TEST(Json, NestingIsLimitedTo256) {
    const auto nested = [](size_t depth) { return std::string(depth, '[') + std::string(depth, ']'); };
    EXPECT_EQ(parse(nested(256), "t.json").asArray().size(), 1u);
    EXPECT_EQ(parseError(nested(257)), "t.json:1:257: arrays and objects nested deeper than 256 levels");
    EXPECT_EQ(parseError(std::string(100000, '[')), "t.json:1:257: arrays and objects nested deeper than 256 levels");
    std::string objects;
    for (int i = 0; i < 100000; ++i) objects += "{\"a\":";
    EXPECT_EQ(parseError(objects), "t.json:1:1281: arrays and objects nested deeper than 256 levels");
}

// ---------------------------------------------------------------------------------------
// Typed accessors

TEST(Json, WrongKindNamesBoth) {
    const Value v = parse("[\"x\", null, 1, [], {}]", "t.json");
    const auto& a = v.asArray();
    EXPECT_EQ(errorOf([&] { a[0].asNumber(); }), "t.json:1:2: expected a number, got a string");
    EXPECT_EQ(errorOf([&] { a[0].asFloat(); }), "t.json:1:2: expected a number, got a string");
    EXPECT_EQ(errorOf([&] { a[0].asUint32(); }), "t.json:1:2: expected a number, got a string");
    EXPECT_EQ(errorOf([&] { a[0].asInt(); }), "t.json:1:2: expected a number, got a string");
    EXPECT_EQ(errorOf([&] { a[1].asBool(); }), "t.json:1:7: expected a boolean, got null");
    EXPECT_EQ(errorOf([&] { a[2].asString(); }), "t.json:1:13: expected a string, got a number");
    EXPECT_EQ(errorOf([&] { a[3].asObject(); }), "t.json:1:16: expected an object, got an array");
    EXPECT_EQ(errorOf([&] { a[3].find("k"); }), "t.json:1:16: expected an object, got an array");
    EXPECT_EQ(errorOf([&] { a[4].asArray(); }), "t.json:1:20: expected an array, got an object");
}

TEST(Json, AsUint32ChecksIntegralAndRange) {
    const auto asUint32 = [](const char* text) { return parse(text, "t.json").asUint32(); };
    EXPECT_EQ(asUint32("0"), 0u);
    EXPECT_EQ(asUint32("-0"), 0u);
    EXPECT_EQ(asUint32("4294967295"), 4294967295u);
    EXPECT_EQ(asUint32("2.0"), 2u);
    EXPECT_EQ(asUint32("2.5e1"), 25u);
    EXPECT_EQ(asUint32("1e2"), 100u);
    EXPECT_EQ(asUint32("2500e-2"), 25u);
    EXPECT_EQ(errorOf([&] { asUint32("1.5"); }), "t.json:1:1: expected an integer, got 1.5");
    EXPECT_EQ(errorOf([&] { asUint32("1e-1"); }), "t.json:1:1: expected an integer, got 1e-1");
    EXPECT_EQ(errorOf([&] { asUint32("4294967296"); }),
              "t.json:1:1: 4294967296 does not fit in a 32-bit unsigned integer (0 to 4294967295)");
    EXPECT_EQ(errorOf([&] { asUint32("-1"); }), "t.json:1:1: -1 does not fit in a 32-bit unsigned integer (0 to 4294967295)");
    EXPECT_EQ(errorOf([&] { asUint32("1e30"); }), "t.json:1:1: 1e30 does not fit in a 32-bit unsigned integer (0 to 4294967295)");
}

TEST(Json, AsIntIsExact) {
    const auto asInt = [](const char* text) { return parse(text, "t.json").asInt(); };
    EXPECT_EQ(asInt("-17"), -17);
    EXPECT_EQ(asInt("9007199254740993"), 9007199254740993);  // not representable as a double
    EXPECT_EQ(asInt("9223372036854775807"), INT64_MAX);
    EXPECT_EQ(asInt("-9223372036854775808"), INT64_MIN);
    EXPECT_EQ(errorOf([&] { asInt("9223372036854775808"); }),
              "t.json:1:1: 9223372036854775808 does not fit in a 64-bit signed integer");
    EXPECT_EQ(errorOf([&] { asInt("-123456789012345678901234"); }),
              "t.json:1:1: -123456789012345678901234 does not fit in a 64-bit signed integer");
    EXPECT_EQ(errorOf([&] { asInt("1.0000000000000000001"); }), "t.json:1:1: expected an integer, got 1.0000000000000000001");
}

TEST(Json, AsFloatRejectsOverflow) {
    const auto asFloat = [](const char* text) { return parse(text, "t.json").asFloat(); };
    EXPECT_EQ(asFloat("0.1"), 0.1f);
    EXPECT_EQ(asFloat("3.4028235e38"), FLT_MAX);
    EXPECT_EQ(asFloat("-3.4028235e38"), -FLT_MAX);
    EXPECT_EQ(asFloat("1e-50"), 0.0f);
    EXPECT_EQ(errorOf([&] { asFloat("1e39"); }), "t.json:1:1: 1e39 does not fit in a 32-bit float");
    EXPECT_EQ(errorOf([&] { asFloat("-3.5e38"); }), "t.json:1:1: -3.5e38 does not fit in a 32-bit float");
}

// ---------------------------------------------------------------------------------------
// ObjectReader

TEST(Json, ObjectReaderReadsAndReportsUnknownKeys) {
    const Value v = parse("{\n"
                          "  \"eye\": [0, 0, 5],\n"
                          "  \"target\": [0, 0, 0],\n"
                          "  \"fovy\": 45\n"
                          "}",
                          "scene.json");
    ObjectReader reader(v, "camera 'overview'");
    EXPECT_EQ(&reader.value(), &v);
    EXPECT_EQ(reader.what(), "camera 'overview'");
    EXPECT_EQ(reader.required("eye").asArray()[2].asFloat(), 5.0f);
    EXPECT_TRUE(reader.required("target").isArray());
    EXPECT_EQ(reader.optional("up"), nullptr);
    EXPECT_EQ(reader.optional("fovY"), nullptr);
    EXPECT_EQ(reader.optional("eye"), v.find("eye"));  // asking twice lists the key once
    EXPECT_EQ(errorOf([&] { reader.finish(); }),
              "scene.json:4:3: unknown key 'fovy' in camera 'overview' (did you mean 'fovY'?); expected one of: eye, "
              "target, up, fovY");
    EXPECT_EQ(errorOf([&] { reader.required("up"); }), "scene.json:1:1: camera 'overview' has no 'up'");
    EXPECT_NE(reader.optional("fovy"), nullptr);
    EXPECT_NO_THROW(reader.finish());
}

TEST(Json, ObjectReaderWithoutSuggestion) {
    const Value v = parse(R"({"size": 1, "colour": 2})", "t.json");
    ObjectReader reader(v, "texture 'grid'");
    reader.required("size");
    EXPECT_EQ(errorOf([&] { reader.finish(); }),
              "t.json:1:13: unknown key 'colour' in texture 'grid'; expected one of: size");
    ObjectReader empty(v, "marker");
    EXPECT_EQ(errorOf([&] { empty.finish(); }), "t.json:1:2: unknown key 'size' in marker; it takes no keys");
}

TEST(Json, ObjectReaderNeedsAnObject) {
    const Value v = parse("\n  [1, 2]", "t.json");
    EXPECT_EQ(errorOf([&] { ObjectReader(v, "camera 'overview'"); }),
              "t.json:2:3: expected an object for camera 'overview', got an array");
}

// ---------------------------------------------------------------------------------------
// Files

TEST(Json, ParseFileReportsMissingFile) {
    EXPECT_EQ(errorOf([] { parseFile("/nonexistent-refray-dir/scene.json"); }),
              "cannot read JSON file '/nonexistent-refray-dir/scene.json': no such file or directory");
}

TEST(Json, ParseFileNamesTheFileInLocations) {
    const std::filesystem::path path = std::filesystem::path(::testing::TempDir()) / "refray_json_test.json";
    {
        std::ofstream out(path, std::ios::binary);
        out << "{\n  \"a\": tru\n}\n";
    }
    EXPECT_EQ(errorOf([&] { parseFile(path); }), path.string() + ":2:8: expected a value, got 'tru'");
    {
        std::ofstream out(path, std::ios::binary);
        out << "{\"a\": [1, 2]}";
    }
    const Value v = parseFile(path);
    EXPECT_EQ(at(v.find("a")->location()), path.string() + ":1:7");
    std::filesystem::remove(path);
}

TEST(Json, PatchReplacesAddsAndRemoves) {
    Value doc = parse(R"({"instances": [{"name": "a", "mask": 1}, {"name": "b"}], "x~/y": 2, "drop": true})", "base.json");
    const Value patch = parse(R"([
  {"op": "replace", "path": "/instances/0/mask", "value": 0},
  {"op": "add", "path": "/instances/1/mask", "value": 7},
  {"op": "add", "path": "/instances/-", "value": {"name": "c"}},
  {"op": "replace", "path": "/x~0~1y", "value": 3},
  {"op": "remove", "path": "/drop"}
])", "lesson.json");
    applyPatch(doc, patch);
    const auto& instances = doc.find("instances")->asArray();
    ASSERT_EQ(instances.size(), 3u);
    EXPECT_EQ(instances[0].find("mask")->asUint32(), 0u);
    EXPECT_EQ(instances[1].find("mask")->asUint32(), 7u);
    EXPECT_EQ(instances[2].find("name")->asString(), "c");
    EXPECT_EQ(doc.find("x~/y")->asUint32(), 3u);
    EXPECT_EQ(doc.find("drop"), nullptr);
    // Patched values keep the patch's location; the rest keep the base's.
    EXPECT_EQ(at(instances[0].find("mask")->location()), "lesson.json:2:59");
    EXPECT_EQ(instances[0].find("name")->location().file, "base.json");
}

TEST(Json, PatchErrorsNameThePath) {
    Value doc = parse(R"({"instances": [{"name": "a"}]})", "base.json");
    EXPECT_EQ(errorOf([&] { applyPatch(doc, parse(R"([{"op": "replace", "path": "/instances/3/mask", "value": 0}])", "l.json")); }),
              "l.json:1:28: path '/instances/3/mask': index 3 is past the end of an array of 1 elements");
    EXPECT_EQ(errorOf([&] { applyPatch(doc, parse(R"([{"op": "replace", "path": "/instances/0/mask", "value": 0}])", "l.json")); }),
              "l.json:1:28: path '/instances/0/mask': no member 'mask' to replace");
    EXPECT_EQ(errorOf([&] { applyPatch(doc, parse(R"([{"op": "replce", "path": "/a", "value": 0}])", "l.json")); }),
              "l.json:1:9: unknown patch op 'replce' (did you mean 'replace'?); expected replace, add or remove");
    EXPECT_EQ(errorOf([&] { applyPatch(doc, parse(R"([{"op": "remove", "path": "instances"}])", "l.json")); }),
              "l.json:1:27: a JSON Pointer starts with '/', got 'instances'");
}
