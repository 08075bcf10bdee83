// Tests docs/scene-format.schema.json and docs/scene-format.md against scenes/scene_loader.cpp (and scenes/loader/): the reference scene
// files and the documented example validate, the example loads and renders, and broken files fail both the schema
// and the loader. The JSON Schema validator below knows exactly the keywords the schema uses; any other keyword in
// the schema is a failure, so the schema cannot lean on a keyword nobody checks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/json.h"
#include "scenes/scene.h"
#include "scenes/scene_loader.h"
#include "tests/scenes/scene_test_support.h"

namespace refray::scenes {
namespace {

using json::Member;
using json::Value;

const std::string kSourceDir = REFRAY_SOURCE_DIR;
const std::string kSchema = kSourceDir + "/docs/scene-format.schema.json";
const std::string kFormatDoc = kSourceDir + "/docs/scene-format.md";
const std::string kProceduray = kSourceDir + "/scenes/proceduray-mandel-julia-pac.json";
const std::string kD3D12 = kSourceDir + "/scenes/d3d12-procedural-geometry.json";

// ---- A JSON Schema (draft 2020-12) validator for the keywords the scene schema uses -----------------------------

// Keywords that only annotate; they never fail an instance.
const std::set<std::string> kAnnotations = {"$schema", "$id", "$comment", "title", "description", "default"};
// Keywords the validator applies.
const std::set<std::string> kAssertions = {
    "$ref", "$defs", "type", "enum", "const",                                               // any instance
    "properties", "additionalProperties", "propertyNames", "required", "dependentRequired",  // objects
    "minProperties",                                                                          //
    "items", "prefixItems", "minItems", "maxItems",                                           // arrays
    "minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum", "multipleOf",               // numbers
    "minLength", "pattern",                                                                   // strings
    "oneOf", "anyOf", "allOf", "if", "then", "else"};                                         // combinations

bool sameJSON(const Value& a, const Value& b) {
    if (a.kind() != b.kind()) return false;
    switch (a.kind()) {
        case Value::Kind::Null: return true;
        case Value::Kind::Bool: return a.asBool() == b.asBool();
        case Value::Kind::Number: return a.asNumber() == b.asNumber();
        case Value::Kind::String: return a.asString() == b.asString();
        case Value::Kind::Array: {
            const auto &x = a.asArray(), &y = b.asArray();
            if (x.size() != y.size()) return false;
            for (size_t i = 0; i < x.size(); ++i)
                if (!sameJSON(x[i], y[i])) return false;
            return true;
        }
        case Value::Kind::Object: {
            if (a.asObject().size() != b.asObject().size()) return false;
            for (const Member& m : a.asObject()) {
                const Value* other = b.find(m.key);
                if (!other || !sameJSON(m.value, *other)) return false;
            }
            return true;
        }
    }
    return false;
}

bool isInteger(const Value& v) {
    return v.isNumber() && std::isfinite(v.asNumber()) && std::floor(v.asNumber()) == v.asNumber();
}

bool hasType(const Value& v, const std::string& type) {
    if (type == "null") return v.isNull();
    if (type == "boolean") return v.isBool();
    if (type == "object") return v.isObject();
    if (type == "array") return v.isArray();
    if (type == "number") return v.isNumber();
    if (type == "string") return v.isString();
    if (type == "integer") return isInteger(v);
    return false;
}

// Length in code points, as JSON Schema counts it.
size_t codePoints(const std::string& s) {
    const auto isLead = [](char c) { return (static_cast<unsigned char>(c) & 0xC0) != 0x80; };
    return size_t(std::count_if(s.begin(), s.end(), isLead));
}

// A string as a JSON value (for propertyNames), by parsing its JSON spelling.
Value stringValue(const std::string& s) {
    std::string text = "\"";
    for (const char c : s) {
        if (c == '"' || c == '\\') {
            text += '\\';
            text += c;
        } else if (static_cast<unsigned char>(c) < 0x20) {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\u%04x", unsigned(static_cast<unsigned char>(c)));
            text += escaped;
        } else {
            text += c;
        }
    }
    return json::parse(text + "\"", "a key");
}

class SchemaValidator {
public:
    explicit SchemaValidator(Value schema) : root_(std::move(schema)) {}

    // Every keyword anywhere in the schema that the validator does not apply, and every malformed subschema or
    // $ref, as "schema path: problem".
    std::vector<std::string> schemaProblems() const {
        std::vector<std::string> problems;
        walk(root_, "#", problems);
        return problems;
    }

    // The errors of `instance`, each "instance path (file:line:column): message"; empty when it validates.
    std::vector<std::string> validate(const Value& instance) const {
        std::vector<std::string> errors;
        check(root_, instance, "", errors);
        return errors;
    }

private:
    // ---- the schema itself

    void walk(const Value& schema, const std::string& path, std::vector<std::string>& problems) const {
        if (schema.isBool()) return;
        if (!schema.isObject()) {
            problems.push_back(path + ": a subschema must be an object or a boolean, got " +
                               std::string(schema.kindName()));
            return;
        }
        for (const Member& m : schema.asObject()) {
            const std::string at = path + "/" + m.key;
            if (!kAnnotations.count(m.key) && !kAssertions.count(m.key)) {
                problems.push_back(at + ": keyword '" + m.key + "' is not supported by this validator");
                continue;
            }
            if (m.key == "properties" || m.key == "$defs") {
                for (const Member& p : m.value.asObject()) walk(p.value, at + "/" + p.key, problems);
            } else if (m.key == "prefixItems" || m.key == "oneOf" || m.key == "anyOf" || m.key == "allOf") {
                const auto& list = m.value.asArray();
                if (list.empty()) problems.push_back(at + ": must not be empty");
                for (size_t i = 0; i < list.size(); ++i) walk(list[i], at + "/" + std::to_string(i), problems);
            } else if (m.key == "additionalProperties" || m.key == "propertyNames" || m.key == "items" ||
                       m.key == "if" || m.key == "then" || m.key == "else") {
                walk(m.value, at, problems);
            } else if (m.key == "$ref") {
                if (!resolve(m.value.asString()))
                    problems.push_back(at + ": cannot resolve '" + m.value.asString() + "'");
            } else if (m.key == "pattern") {
                try {
                    std::regex(m.value.asString(), std::regex::ECMAScript);
                } catch (const std::regex_error& e) {
                    problems.push_back(at + ": bad pattern: " + e.what());
                }
            }
        }
    }

    // Only local references into $defs: "#/$defs/NAME".
    const Value* resolve(const std::string& ref) const {
        const std::string prefix = "#/$defs/";
        if (ref.compare(0, prefix.size(), prefix) != 0) return nullptr;
        const Value* defs = root_.find("$defs");
        return defs ? defs->find(ref.substr(prefix.size())) : nullptr;
    }

    // ---- an instance

    static std::string describe(const std::string& path, const Value& instance) {
        return (path.empty() ? "/" : path) + " (" + json::toString(instance.location()) + ")";
    }

    bool matches(const Value& schema, const Value& instance, const std::string& path) const {
        std::vector<std::string> ignored;
        return check(schema, instance, path, ignored);
    }

    // Appends the errors of `instance` against `schema`; returns whether there were none.
    bool check(const Value& schema, const Value& instance, const std::string& path,
               std::vector<std::string>& errors) const {
        const size_t before = errors.size();
        const auto fail = [&](const std::string& message) {
            errors.push_back(describe(path, instance) + ": " + message);
        };
        if (schema.isBool()) {
            if (!schema.asBool()) fail("not allowed here");
            return errors.size() == before;
        }

        if (const Value* ref = schema.find("$ref")) {
            if (const Value* target = resolve(ref->asString()))
                check(*target, instance, path, errors);
            else
                fail("unsupported $ref '" + ref->asString() + "'");
        }
        if (const Value* type = schema.find("type")) {
            std::vector<std::string> types;
            if (type->isString()) {
                types.push_back(type->asString());
            } else {
                for (const Value& t : type->asArray()) types.push_back(t.asString());
            }
            std::string list;
            bool any = false;
            for (const std::string& t : types) {
                any = any || hasType(instance, t);
                list += (list.empty() ? "" : " or ") + t;
            }
            if (!any) {
                fail("expected " + list + ", got " + std::string(instance.kindName()));
                return false;  // the other keywords would only repeat it
            }
        }
        if (const Value* e = schema.find("enum")) {
            std::string list;
            bool found = false;
            for (const Value& option : e->asArray()) {
                found = found || sameJSON(option, instance);
                const std::string shown =
                    option.isString() ? "'" + option.asString() + "'" : std::string(option.kindName());
                list += (list.empty() ? "" : ", ") + shown;
            }
            if (!found) fail("not one of " + list);
        }
        if (const Value* c = schema.find("const"))
            if (!sameJSON(*c, instance))
                fail(c->isString() ? "expected '" + c->asString() + "'" : "does not equal the schema's constant");

        if (instance.isObject()) checkObject(schema, instance, path, errors, fail);
        if (instance.isArray()) checkArray(schema, instance, path, errors, fail);
        if (instance.isNumber()) checkNumber(schema, instance, fail);
        if (instance.isString()) {
            const std::string& s = instance.asString();
            if (const Value* n = schema.find("minLength"))
                if (double(codePoints(s)) < n->asNumber()) fail("shorter than " + n->numberText() + " characters");
            if (const Value* p = schema.find("pattern"))
                if (!std::regex_search(s, std::regex(p->asString(), std::regex::ECMAScript)))
                    fail("'" + s + "' does not match " + p->asString());
        }

        if (const Value* all = schema.find("allOf"))
            for (const Value& s : all->asArray()) check(s, instance, path, errors);
        if (const Value* any = schema.find("anyOf")) {
            bool found = false;
            for (const Value& s : any->asArray()) found = found || matches(s, instance, path);
            if (!found) fail("matches none of the anyOf alternatives");
        }
        if (const Value* one = schema.find("oneOf")) {
            std::vector<std::string> firstErrors;
            int count = 0;
            for (const Value& s : one->asArray()) {
                std::vector<std::string> branch;
                if (check(s, instance, path, branch)) {
                    ++count;
                } else {
                    firstErrors.push_back(branch.empty() ? "?" : branch.front());
                }
            }
            if (count == 0) {
                std::string detail;
                for (size_t i = 0; i < firstErrors.size(); ++i)
                    detail += (i ? "; alternative " : "alternative ") + std::to_string(i + 1) + ": " + firstErrors[i];
                fail("matches none of the oneOf alternatives (" + detail + ")");
            } else if (count > 1) {
                fail("matches " + std::to_string(count) + " oneOf alternatives, not exactly one");
            }
        }
        if (const Value* condition = schema.find("if")) {
            const Value* branch = schema.find(matches(*condition, instance, path) ? "then" : "else");
            if (branch) check(*branch, instance, path, errors);
        }
        return errors.size() == before;
    }

    template <class Fail>
    void checkObject(const Value& schema, const Value& instance, const std::string& path,
                     std::vector<std::string>& errors, const Fail& fail) const {
        const Value* properties = schema.find("properties");
        const Value* additional = schema.find("additionalProperties");
        const Value* names = schema.find("propertyNames");
        for (const Member& m : instance.asObject()) {
            const std::string at = path + "/" + m.key;
            const Value* declared = properties ? properties->find(m.key) : nullptr;
            if (declared) {
                check(*declared, m.value, at, errors);
            } else if (additional) {
                if (additional->isBool() && !additional->asBool()) {
                    std::string expected;
                    if (properties)
                        for (const Member& p : properties->asObject())
                            expected += (expected.empty() ? "" : ", ") + p.key;
                    errors.push_back(describe(path, instance) + ": unknown key '" + m.key + "'" +
                                     (expected.empty() ? "" : "; expected one of: " + expected));
                } else {
                    check(*additional, m.value, at, errors);
                }
            }
            if (names) check(*names, stringValue(m.key), at, errors);
        }
        if (const Value* required = schema.find("required"))
            for (const Value& key : required->asArray())
                if (!instance.find(key.asString())) fail("missing required key '" + key.asString() + "'");
        if (const Value* dependent = schema.find("dependentRequired"))
            for (const Member& d : dependent->asObject())
                if (instance.find(d.key))
                    for (const Value& key : d.value.asArray())
                        if (!instance.find(key.asString()))
                            fail("'" + d.key + "' needs '" + key.asString() + "' beside it");
        if (const Value* n = schema.find("minProperties"))
            if (double(instance.asObject().size()) < n->asNumber()) fail("needs at least " + n->numberText() + " keys");
    }

    template <class Fail>
    void checkArray(const Value& schema, const Value& instance, const std::string& path,
                    std::vector<std::string>& errors, const Fail& fail) const {
        const auto& elements = instance.asArray();
        const std::string has = "has " + std::to_string(elements.size()) + " elements; ";
        size_t first = 0;
        if (const Value* prefix = schema.find("prefixItems")) {
            const auto& schemas = prefix->asArray();
            for (; first < schemas.size() && first < elements.size(); ++first)
                check(schemas[first], elements[first], path + "/" + std::to_string(first), errors);
            first = schemas.size();
        }
        if (const Value* items = schema.find("items"))
            for (size_t i = first; i < elements.size(); ++i) {
                if (items->isBool() && !items->asBool()) {
                    fail(has + "at most " + std::to_string(first) + " are allowed");
                    break;
                }
                check(*items, elements[i], path + "/" + std::to_string(i), errors);
            }
        if (const Value* n = schema.find("minItems"))
            if (double(elements.size()) < n->asNumber())
                fail(has + "at least " + n->numberText() + " are needed");
        if (const Value* n = schema.find("maxItems"))
            if (double(elements.size()) > n->asNumber())
                fail(has + "at most " + n->numberText() + " are allowed");
    }

    template <class Fail>
    static void checkNumber(const Value& schema, const Value& instance, const Fail& fail) {
        const double d = instance.asNumber();
        const std::string& text = instance.numberText();
        if (const Value* v = schema.find("minimum"))
            if (d < v->asNumber()) fail(text + " is below the minimum " + v->numberText());
        if (const Value* v = schema.find("maximum"))
            if (d > v->asNumber()) fail(text + " is above the maximum " + v->numberText());
        if (const Value* v = schema.find("exclusiveMinimum"))
            if (d <= v->asNumber()) fail(text + " is not above " + v->numberText());
        if (const Value* v = schema.find("exclusiveMaximum"))
            if (d >= v->asNumber()) fail(text + " is not below " + v->numberText());
        if (const Value* v = schema.find("multipleOf"))
            if (std::fmod(d, v->asNumber()) != 0.0) fail(text + " is not a multiple of " + v->numberText());
    }

    Value root_;
};

// ---- Helpers -----------------------------------------------------------------------------------------------------

using testing::readText;

const SchemaValidator& sceneSchema() {
    static const SchemaValidator validator(json::parseFile(kSchema));
    return validator;
}

std::vector<std::string> schemaErrors(const std::string& text, const std::string& name) {
    return sceneSchema().validate(json::parse(text, name));
}

std::string joinedLines(const std::vector<std::string>& lines) {
    std::string s;
    for (const std::string& l : lines) s += l + "\n";
    return s;
}

// The first ```json fenced block of docs/scene-format.md: the documented example scene.
std::string documentedExample() {
    const std::string doc = readText(kFormatDoc);
    const std::string fence = "```json\n";
    const size_t begin = doc.find(fence);
    EXPECT_NE(begin, std::string::npos) << "no ```json block in " << kFormatDoc;
    if (begin == std::string::npos) return "";
    const size_t end = doc.find("\n```", begin + fence.size());
    EXPECT_NE(end, std::string::npos) << "the first ```json block of " << kFormatDoc << " is not closed";
    return doc.substr(begin + fence.size(), end - begin - fence.size() + 1);
}

using testing::edited;
using testing::loadError;

// ---- The validator -------------------------------------------------------------------------------------------------

TEST(SceneSchema, UsesOnlyKeywordsTheValidatorApplies) {
    const Value schema = json::parseFile(kSchema);
    EXPECT_EQ(schema.find("$schema")->asString(), "https://json-schema.org/draft/2020-12/schema");
    const std::vector<std::string> problems = sceneSchema().schemaProblems();
    EXPECT_TRUE(problems.empty()) << joinedLines(problems);
}

TEST(SceneSchema, ValidatorReportsUnknownKeywordsAndBadReferences) {
    const SchemaValidator validator(json::parse(R"({
      "type": "object",
      "properties": {"a": {"type": "array", "minContains": 1}, "b": {"$ref": "#/$defs/missing"}},
      "$defs": {"c": {"unevaluatedProperties": false}}
    })", "schema.json"));
    const std::string problems = joinedLines(validator.schemaProblems());
    EXPECT_CONTAINS(problems, "#/properties/a/minContains: keyword 'minContains' is not supported");
    EXPECT_CONTAINS(problems, "#/properties/b/$ref: cannot resolve '#/$defs/missing'");
    EXPECT_CONTAINS(problems, "#/$defs/c/unevaluatedProperties: keyword 'unevaluatedProperties' is not supported");
}

TEST(SceneSchema, ValidatorAppliesItsKeywords) {
    const SchemaValidator validator(json::parse(R"({
      "type": "object",
      "properties": {
        "n": {"type": "integer", "minimum": 0, "maximum": 4096, "multipleOf": 32},
        "v": {"type": "array", "prefixItems": [{"type": "number"}, {"const": 1}], "items": false, "minItems": 2},
        "s": {"type": "string", "pattern": "^b[0-9]+$"},
        "o": {"oneOf": [{"required": ["x"]}, {"required": ["y"]}]},
        "m": {"type": "object", "propertyNames": {"pattern": "^[^@]"},
              "additionalProperties": {"type": ["string", "null"]}}
      },
      "required": ["n"],
      "dependentRequired": {"v": ["s"]},
      "additionalProperties": false,
      "if": {"properties": {"n": {"const": 0}}},
      "then": {"required": ["o"]}
    })", "schema.json"));
    const auto errors = [&](const std::string& text) {
        return joinedLines(validator.validate(json::parse(text, "i.json")));
    };
    EXPECT_EQ(errors(R"({"n": 64, "v": [2.5, 1.0], "s": "b12", "o": {"x": 1}, "m": {"k": null, "l": "x"}})"), "");
    EXPECT_CONTAINS(errors(R"({"n": 48})"), "48 is not a multiple of 32");
    EXPECT_CONTAINS(errors(R"({"n": 2.5})"), "expected integer, got a number");
    EXPECT_CONTAINS(errors(R"({"n": 32, "v": [1, 1, 1], "s": "b"})"), "at most 2 are allowed");
    EXPECT_CONTAINS(errors(R"({"n": 32, "v": [1, 2], "s": "b1"})"), "does not equal the schema's constant");
    EXPECT_CONTAINS(errors(R"({"n": 32, "v": [1, 1]})"), "'v' needs 's' beside it");
    EXPECT_CONTAINS(errors(R"({"n": 32, "s": "t0"})"), "'t0' does not match ^b[0-9]+$");
    EXPECT_CONTAINS(errors(R"({"n": 32, "o": {"x": 1, "y": 2}})"), "matches 2 oneOf alternatives");
    EXPECT_CONTAINS(errors(R"({"n": 32, "o": {}})"), "matches none of the oneOf alternatives");
    EXPECT_CONTAINS(errors(R"({"n": 32, "m": {"@k": "x"}})"), "'@k' does not match ^[^@]");
    EXPECT_CONTAINS(errors(R"({"n": 32, "m": {"k": 1}})"), "expected string or null, got a number");
    EXPECT_CONTAINS(errors(R"({"n": 0})"), "missing required key 'o'");
    EXPECT_CONTAINS(errors(R"({"n": 32, "x": 1})"), "unknown key 'x'");
    EXPECT_CONTAINS(errors(R"({})"), "missing required key 'n'");
}

// ---- The scene files -----------------------------------------------------------------------------------------------

TEST(SceneSchema, ReferenceScenesValidate) {
    size_t files = 0;
    for (const auto& f : std::filesystem::directory_iterator(kSourceDir + "/scenes")) {
        if (f.path().extension() != ".json") continue;
        ++files;
        const std::vector<std::string> errors = sceneSchema().validate(json::parseFile(f.path()));
        EXPECT_TRUE(errors.empty()) << f.path() << "\n" << joinedLines(errors);
    }
    EXPECT_GE(files, 4u);
}

TEST(SceneSchema, DocumentedExampleValidatesLoadsAndRenders) {
    const std::string text = documentedExample();
    ASSERT_FALSE(text.empty());
    const std::vector<std::string> errors = schemaErrors(text, "scene-format.md example");
    EXPECT_TRUE(errors.empty()) << joinedLines(errors);

    SceneDesc desc = parseScene(text, "scene-format.md example");
    // What the document says about the example's auto layout: the ground's records are 0 and 1, the spheres'
    // are 2 and 3, so a shadow ray that hits the spheres uses record 1 + 2·0 + 2 = 3.
    ASSERT_EQ(desc.instances.size(), 2u);
    EXPECT_EQ(desc.instances[0].contribution, 0u);
    EXPECT_EQ(desc.instances[1].contribution, 2u);
    ASSERT_EQ(desc.hitGroupRecords.size(), 4u);
    EXPECT_EQ(desc.hitGroupRecords[1 + 2 * 0 + 2].hitGroup, "Spheres_Shadow");
    EXPECT_EQ(desc.missRecords, (std::vector<std::string>{"MyMissShader", "MyMissShader_ShadowRay"}));

    Scene scene(std::move(desc));
    RenderSettings settings;
    settings.width = 32;
    settings.height = 18;
    settings.threads = 1;
    const RenderResult result = scene.render(settings);
    EXPECT_TRUE(result.dispatch.diagnostics.empty());
    for (const vec4& p : result.image.pixels())
        ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z) && std::isfinite(p.w));
}

TEST(SceneSchema, DocumentedRecordIndicesHold) {
    // docs/scene-format.md, "Worked example": R + M·G + C for the shadow ray (R = 1, M = 2).
    const SceneDesc proceduray = loadSceneFile(kProceduray);
    EXPECT_EQ(proceduray.instances[3].name, "pacmanB");
    EXPECT_EQ(proceduray.instances[3].contribution, 6u);
    EXPECT_EQ(proceduray.hitGroupRecords[1 + 2 * 0 + 6].hitGroup, "HitGroup_Pacman_Shadow");
    EXPECT_EQ(proceduray.hitGroupRecords[1 + 2 * 0 + 6].arguments[1].dwords, (std::vector<uint32_t>{2, 1}));
    const SceneDesc d3d12 = loadSceneFile(kD3D12);
    EXPECT_EQ(d3d12.instances[1].contribution, 2u);
    EXPECT_EQ(d3d12.hitGroupRecords[1 + 2 * 1 + 2].hitGroup, "MyHitGroup_AABB_AnalyticPrimitive_ShadowRay");
}

// The ```json block under "### A complete path-tracer example" of docs/scene-format.md, and where it says to save it
// (its model paths are relative to scenes/).
std::string documentedPathTracerExample() {
    const std::string doc = readText(kFormatDoc);
    const size_t heading = doc.find("### A complete path-tracer example");
    EXPECT_NE(heading, std::string::npos) << "no path-tracer example in " << kFormatDoc;
    const std::string fence = "```json\n";
    const size_t begin = heading == std::string::npos ? heading : doc.find(fence, heading);
    if (begin == std::string::npos) return "";
    const size_t end = doc.find("\n```", begin + fence.size());
    return doc.substr(begin + fence.size(), end - begin - fence.size() + 1);
}
const std::string kPathTracerExample = kSourceDir + "/scenes/cornell-walls.json";

TEST(SceneSchema, DocumentedPathTracerExampleValidatesLoadsAndRenders) {
    const std::string text = documentedPathTracerExample();
    ASSERT_FALSE(text.empty());
    const std::vector<std::string> errors = schemaErrors(text, "path-tracer example");
    EXPECT_TRUE(errors.empty()) << joinedLines(errors);

    SceneDesc desc = parseScene(text, kPathTracerExample);
    // What the document says: InstanceIDs 0 and 1, contributions 0 and 2, the light quad's two triangles, one null
    // texture descriptor per texture table.
    ASSERT_EQ(desc.instances.size(), 2u);
    EXPECT_EQ(desc.instances[1].instanceID, 1u);
    EXPECT_EQ(desc.instances[1].contribution, 2u);
    EXPECT_EQ(desc.hitGroupRecords.at(0 + 2 * 0 + 2).hitGroup, "PT_HitGroup");
    EXPECT_EQ(desc.modelBuffers.modelRanges.at(0).indexCount, 30u);
    EXPECT_EQ(desc.modelBuffers.modelRanges.at(0).materialCount, 3u);
    EXPECT_EQ(desc.lightTriangleCount(), 2u);
    EXPECT_EQ(desc.globalArguments.at(4).table.size(), 1u);

    Scene scene(std::move(desc));
    RenderSettings settings;
    settings.width = settings.height = 8;
    settings.spp = 2;
    settings.threads = 2;
    const Image image = scene.render(settings).image;
    float sum = 0.0f;
    for (const vec4& p : image.pixels()) sum += p.r + p.g + p.b;
    EXPECT_GT(sum, 0.0f);
}

// What the schema refuses of a path-tracer scene, and the loader too.
TEST(SceneSchema, PathTracerRulesFail) {
    const std::string text = documentedPathTracerExample();
    const auto broken = [&](const char* from, const char* to, const char* schemaMessage) {
        const std::string b = edited(text, from, to);
        EXPECT_CONTAINS(joinedLines(schemaErrors(b, "broken.json")), schemaMessage);
        try {
            parseScene(b, kPathTracerExample);
            ADD_FAILURE() << to << ": the loader accepts what the schema refuses";
        } catch (const Error&) {
        }
    };
    broken("\"imageSize\":", "\"light\": {\"position\": [0, 0, 0, 1], \"ambientColor\": [0, 0, 0, 1], \"diffuseColor\": [1, 1, 1, 1]}, \"imageSize\":",
           "/light");
    broken("\"payload\": \"ShadowPayload\"}", "\"payload\": \"ShadowPayload\", \"traceRay\": {\"multiplier\": 1}}", "/traceRay");
    broken("\"filter\": \"anisotropic\"", "\"filter\": \"anisotropik\"", "not one of 'point'");
    broken("\"space\": 6, \"count\": \"unbounded\"", "\"space\": 6, \"count\": \"unbound\"", "matches none of the oneOf");
    broken("[{\"textures\": \"normal\"}]", "[{\"textures\": \"normals\"}]", "matches none of the oneOf");
    broken("\"model\": \"light\"}]}", "\"model\": \"light\", \"mesh\": \"x.obj\"}]}", "matches none of the oneOf");
    broken("\"maxBounces\": 4}", "\"maxBounces\": 4, \"debugFlag\": 1}", "/debugFlag");
    broken("\"generate\": \"lightTriangles\"}", "\"generate\": \"lightTriangles\", \"stride\": 64}", "matches none of the oneOf");
}

// Each broken variant of the documented example fails the schema with `schemaMessage` and fails the loader too.
struct Broken {
    const char* what;
    const char* from;
    const char* to;
    const char* schemaMessage;
};

void expectBroken(const Broken& b) {
    const std::string text = edited(documentedExample(), b.from, b.to);
    const std::string errors = joinedLines(schemaErrors(text, "broken.json"));
    EXPECT_CONTAINS(errors, b.schemaMessage);
    EXPECT_NE(loadError(text), "") << b.what << ": the loader accepts what the schema refuses";
}

TEST(SceneSchema, UnknownKeysFail) {
    expectBroken({"camera typo", "\"fovYDegrees\": 45", "\"fovYDegrees\": 45, \"fovy\": 45", "unknown key 'fovy'"});
    expectBroken({"top-level typo", "\"imageSize\":", "\"imageSzie\":", "unknown key 'imageSzie'"});
    expectBroken({"cbv with a struct", "\"kind\": \"cbv\", \"register\": \"b0\"}",
                  "\"kind\": \"cbv\", \"register\": \"b0\", \"struct\": \"PrimitiveConstantBuffer\"}",
                  "matches none of the oneOf alternatives"});
}

TEST(SceneSchema, WrongEnumsFail) {
    expectBroken({"camera model", "\"model\": \"directxmath-lh\"", "\"model\": \"directxmath-rh\"",
                  "not one of 'miniengine'"});
    expectBroken({"buffer format", "\"format\": \"uint16\"", "\"format\": \"uint8\"",
                  "matches none of the oneOf alternatives"});
    expectBroken({"geometry flag", "\"aabbs\", \"flags\": [\"OPAQUE\"]", "\"aabbs\", \"flags\": [\"OPAQUE_GEOMETRY\"]",
                  "not one of 'OPAQUE', 'NO_DUPLICATE_ANYHIT_INVOCATION'"});
    expectBroken({"register class", "\"kind\": \"cbv\", \"register\": \"b0\"",
                  "\"kind\": \"cbv\", \"register\": \"t0\"", "'t0' does not match ^b[0-9]+$"});
}

TEST(SceneSchema, MissingRequiredKeysFail) {
    expectBroken({"light", "\"light\":", "\"lamp\":", "missing required key 'light'"});
    expectBroken({"ray type miss", "{\"name\": \"Radiance\", \"miss\": \"MyMissShader\", \"payload\": \"RayPayload\"}",
                  "{\"name\": \"Radiance\", \"payload\": \"RayPayload\"}", "missing required key 'miss'"});
    expectBroken({"procedural hit group without intersection",
                  "\"intersection\": \"MyIntersectionShader_AnalyticPrimitive\", \"closestHit\"",
                  "\"closestHit\"", "missing required key 'intersection'"});
}

TEST(SceneSchema, EffectsBlockValidatesAndBadOnesFail) {
    const std::string text =
        edited(documentedExample(), "\"imageSize\":", "\"effects\": {\"shadows\": false, \"reflectionDepth\": 2}, \"imageSize\":");
    const std::vector<std::string> errors = schemaErrors(text, "effects.json");
    EXPECT_TRUE(errors.empty()) << joinedLines(errors);
    EXPECT_EQ(loadError(text), "");
    expectBroken({"effects typo", "\"imageSize\":", "\"effects\": {\"shadow\": false}, \"imageSize\":",
                  "unknown key 'shadow'"});
    expectBroken({"effects shadows type", "\"imageSize\":", "\"effects\": {\"shadows\": 0}, \"imageSize\":",
                  "expected boolean, got a number"});
    expectBroken({"effects depth range", "\"imageSize\":", "\"effects\": {\"reflectionDepth\": 0}, \"imageSize\":",
                  "is below the minimum 1"});
}

TEST(SceneSchema, LayoutRulesFail) {
    // Auto layout computes contributions; explicit layout needs the table and a contribution per instance.
    expectBroken({"contribution in auto layout", "\"blas\": \"SpheresBox\", \"mask\": 1,",
                  "\"blas\": \"SpheresBox\", \"mask\": 1, \"contribution\": 2,", "/instances/1/contribution"});
    expectBroken({"explicit layout without a table", "\"shaderLibrary\": \"d3d12-procedural-geometry\",",
                  "\"shaderLibrary\": \"d3d12-procedural-geometry\", \"layout\": \"explicit\",",
                  "missing required key 'shaderTable'"});
}

}  // namespace
}  // namespace refray::scenes
