// What the parts of a scene file (docs/scene-format.md) share while scenes/scene_loader.cpp reads them, and the
// reader of each part, one file per part in scenes/loader/. Internal to the scene loader. Every reader reports bad
// input through json::Value::fail, so the error names the file, line and column of the value it is about.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/json.h"
#include "core/math.h"
#include "scenes/model.h"
#include "scenes/scene_desc.h"

namespace refray::scenes::loader {

using json::ObjectReader;
using json::Value;

// A root parameter's name, which scene files bind arguments by, and its struct.
struct ParameterInfo {
    std::string name;
    int32_t structIndex = -1;  // constants with a declared struct
};

struct SignatureInfo {
    std::vector<ParameterInfo> parameters;
};

// The scene being filled in, and what the parts read earlier keep for the parts after them (names to resolve,
// struct layouts, the loaded models, where each record was written).
struct ParseContext {
    explicit ParseContext(SceneDesc& sceneDesc) : scene(sceneDesc) {}

    SceneDesc& scene;
    const ShaderLibraryBinding* binding = nullptr;
    std::shared_ptr<dxr::ShaderLibrary> library;
    const Value* values = nullptr;
    std::vector<std::string> structNames;
    std::vector<std::string> hitGroupNames, localNames, blasNames, instanceNames, modelNames;
    std::vector<Model> models;  // scene.models, loaded
    SignatureInfo globalInfo;
    std::vector<SignatureInfo> localInfo;
    std::vector<const Value*> recordValues;  // auto layout: each instance's "records"
    std::vector<const Value*> recordWhere;   // per hit-group record: where its hit group was named
};

// ---- readers.cpp: names, numbers, vectors and flags

// An index into `names` for the string `value`, or an error at its location with a "did you mean".
uint32_t resolveName(const Value& value, const std::vector<std::string>& names, const std::string& kind);
std::string nonEmptyName(const Value& value, const std::string& what);

template <int N>
glm::vec<N, float> floatVector(const Value& value, const std::string& what) {
    const auto& a = value.asArray();
    if (a.size() != size_t(N))
        value.fail(what + " needs " + std::to_string(N) + " numbers, got " + std::to_string(a.size()));
    glm::vec<N, float> v;
    for (int i = 0; i < N; ++i) v[i] = a[size_t(i)].asFloat();
    return v;
}

glm::dvec3 doubleVector3(const Value& value, const std::string& what);
double finiteNumber(const Value& value, const std::string& what);
// Flags given as an array of names (without the D3D12 prefix).
uint32_t flagSet(const Value& value, const std::vector<std::pair<std::string, uint32_t>>& known, const std::string& what);

// ---- structs.cpp: "structs" and constant values

using ScalarKind = StructField::Kind;

uint32_t encodeScalar(const Value& v, ScalarKind kind, const std::string& what);
void parseStructs(ParseContext& ctx, const Value& value);
// A constants argument: a named entry of "values" or an inline object, encoded with the parameter's struct.
std::vector<uint32_t> constantValue(const ParseContext& ctx, const Value& value, int32_t structIndex, uint32_t num32,
                                    const std::string& what);

// ---- pipeline.cpp: "pipeline", "rayTypes" and "hitGroups"

void parsePipeline(ParseContext& ctx, const Value& value);
// The library's export `nameValue` names, which must be a `stage` shader.
const dxr::ShaderExport& requireExport(const ParseContext& ctx, const Value& nameValue, dxr::ShaderStage stage);
void parseRayTypes(ParseContext& ctx, const Value& value);
void parseHitGroups(ParseContext& ctx, const Value& value);

// ---- root_signatures.cpp: "rootSignatures"

void parseRootSignatures(ParseContext& ctx, const Value& value);

// ---- models.cpp: "models" and the buffers generated from them

void parseModels(ParseContext& ctx, const Value& value);
// The model buffer kinds, as "generate" names them; the first four need only the models, the last two the
// instances too.
const std::vector<std::pair<std::string, BufferDesc::Kind>>& modelBufferKinds();
// The kind of a model buffer that needs only the models ({"generate": "modelVertices"}, ...), else nullopt.
std::optional<BufferDesc::Kind> staticModelKind(const Value& buffer);
// A buffer generated from the models: {"generate": KIND} and no other key.
void addModelBuffer(ParseContext& ctx, const json::Member& m, BufferDesc::Kind kind);

// ---- buffers.cpp: "buffers"

uint32_t addBuffer(ParseContext& ctx, BufferDesc buffer, const Value& where);
// The data buffers, and the model buffers that need only the models: before the geometry that reads them.
void parseDataBuffers(ParseContext& ctx, const Value& value);
// The buffers generated from the instances and the geometry: after them.
void parseGeneratedBuffers(ParseContext& ctx, const Value& value);
// A buffer that geometry reads: one with data, not one generated each frame.
int32_t dataBuffer(const ParseContext& ctx, const Value& nameValue);
int32_t dataOrGeneratedBuffer(const ParseContext& ctx, const Value& nameValue);

// ---- geometry.cpp: "bottomLevel"

void parseBottomLevel(ParseContext& ctx, const Value& value);

// ---- instances.cpp: "instances"

void parseInstances(ParseContext& ctx, const Value& value);

// ---- shader_table.cpp: the hit-group records, in auto or explicit layout

// Auto layout: each instance's "records", one per geometry and ray type, in instance order.
void buildAutoLayout(ParseContext& ctx);
// Explicit layout: "shaderTable".
void parseExplicitTable(ParseContext& ctx, const Value& value);
// One local root signature per hit group, derived from the records (ASSOC-3).
void deriveAssociations(ParseContext& ctx);

// ---- global_arguments.cpp: "globalArguments"

void parseGlobalArguments(ParseContext& ctx, const Value& value);

// ---- cameras.cpp: "cameras", "light", "time" and "effects"

void parseCameras(ParseContext& ctx, const Value& value, const Value* defaultCamera);
void parseLight(ParseContext& ctx, const Value& value);
void parseTime(ParseContext& ctx, const Value& value);
void parseEffects(ParseContext& ctx, const Value& value);

// ---- lesson.cpp: lesson files

// A lesson file (format refray-lesson/1): its base scene (or base lesson) with a JSON Patch applied. Returns the
// patched document (`root` itself when it is no lesson); `hashed` collects the text of every file in the chain,
// `lesson` the outermost lesson's facts.
Value resolveLesson(Value root, const std::string& fileName, uint32_t depth, std::string& hashed, LessonDesc& lesson);

}  // namespace refray::scenes::loader
