#include "inspect/explain.h"

#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <map>
#include <sstream>

#include "core/error.h"
#include "core/json_writer.h"
#include "core/strings.h"

namespace refray::scenes {

using dxr::TraceEvent;
using Kind = TraceEvent::Kind;

void EventRecorder::onEvent(const TraceEvent& e) {
    RecordedEvent r;
    r.event = e;
    r.table = std::string(e.table);
    r.exportName = std::string(e.exportName);
    r.note = std::string(e.note);
    if (e.payloadTypeId) {
        dxr::TypeTag tag;
        tag.id = e.payloadTypeId;
        tag.size = e.payloadSize;
        tag.mangledName = e.payloadTypeName.data();
        r.payloadType = tag.name();
        r.payload.assign(e.payload, e.payload + e.payloadSize);
    }
    r.event.table = {};
    r.event.exportName = {};
    r.event.note = {};
    r.event.payloadTypeName = {};
    r.event.payload = nullptr;
    events.push_back(std::move(r));
}

Explanation explainPixel(Scene& scene, const RenderSettings& settings, uint32_t x, uint32_t y) {
    REFRAY_CHECK(x < settings.width && y < settings.height,
                 "--pixel " << x << "," << y << " is outside the " << settings.width << "x" << settings.height
                            << " image (x in 0.." << settings.width - 1 << ", y in 0.." << settings.height - 1 << ")");
    REFRAY_CHECK(settings.spp == 1, "refray explain follows the GPU's one ray generation thread per pixel; --spp must be 1");
    EventRecorder recorder;
    RenderSettings s = settings;
    s.region = dxr::LaunchRegion{x, y, 1, 1};
    s.observer = &recorder;
    s.onError = dxr::OnError::Stop;
    s.threads = 1;
    s.progress = {};

    Explanation out;
    const SceneDesc& desc = scene.desc();
    out.scene = desc.name;
    out.camera = desc.camera(settings.camera).name;
    out.time = settings.time ? shortestFloat(*settings.time) : desc.defaultTimeText;
    out.precision = std::string(procedural::toString(settings.precision));
    out.width = settings.width;
    out.height = settings.height;
    out.x = x;
    out.y = y;
    try {
        RenderResult result = scene.render(s);
        out.pixel = result.image.at(x, y);
        for (const dxr::Diagnostic& w : result.dispatch.diagnostics.warnings()) out.warnings.push_back(w);
    } catch (const dxr::DxrError& e) {
        out.error = e.diagnostic();
    }
    out.events = std::move(recorder.events);
    return out;
}

// ---- Every pixel in brief ------------------------------------------------------------------------------

namespace {

class TreeRecorder : public dxr::TraceObserver {
public:
    TreeRecorder(const SceneDesc& desc, PixelTrees& out) : desc_(desc), out_(out), open_(out.rays.size()) {}
    void onEvent(const TraceEvent& e) override {
        if (e.kind != Kind::TraceRay && e.kind != Kind::TraceRayEnd) return;
        const size_t pixel = size_t(e.launchIndex.y) * out_.width + e.launchIndex.x;
        std::vector<RaySummary>& rays = out_.rays[pixel];
        std::vector<uint32_t>& open = open_[pixel];
        if (e.kind == Kind::TraceRay) {
            RaySummary r;
            r.depth = e.depth;
            r.rayContribution = e.rayContribution;
            r.multiplier = e.multiplier;
            r.missShaderIndex = e.missShaderIndex;
            r.rayFlags = e.rayFlags;
            open.push_back(uint32_t(rays.size()));
            rays.push_back(r);
            return;
        }
        if (open.empty()) return;
        RaySummary& r = rays[open.back()];
        open.pop_back();
        r.hit = e.committed;
        if (!e.committed) return;
        r.instanceIndex = e.instanceIndex;
        r.geometryIndex = e.geometryIndex;
        r.primitiveIndex = e.primitiveIndex;
        r.t = e.t;
        const uint32_t c = e.instanceIndex < desc_.instances.size() ? desc_.instances[e.instanceIndex].contribution : 0;
        r.terms = dxr::hitGroupRecordIndex(e.rayContribution, e.multiplier, e.geometryIndex, c);
    }

private:
    const SceneDesc& desc_;
    PixelTrees& out_;
    std::vector<std::vector<uint32_t>> open_;  // per pixel: the TraceRays in flight
};

}  // namespace

PixelTrees explainAllPixels(Scene& scene, const RenderSettings& settings) {
    REFRAY_CHECK(settings.spp == 1, "refray explain follows the GPU's one ray generation thread per pixel; --spp must be 1");
    PixelTrees out;
    out.width = settings.width;
    out.height = settings.height;
    out.rays.resize(size_t(settings.width) * settings.height);
    TreeRecorder recorder(scene.desc(), out);
    RenderSettings s = settings;
    s.observer = &recorder;
    RenderResult result = scene.render(s);
    out.image = std::move(result.image);
    out.dispatch = std::move(result.dispatch);
    return out;
}

// ---- Payload layouts of the registered shader libraries -----------------------------------------------

namespace {

struct PayloadField {
    const char* name;
    char kind;  // 'f' float, 'u' uint, 'i' int, 'b' a 32-bit HLSL bool
    uint32_t components;
};
struct PayloadLayout {
    const char* typeName;
    std::vector<PayloadField> fields;
};

const std::vector<PayloadLayout>& payloadLayouts() {
    static const std::vector<PayloadLayout> layouts = {
        {"refray::procedural::proceduray::RayPayload",
         {{"color", 'f', 4}, {"recursionDepth", 'u', 1}, {"dist", 'f', 1}, {"count", 'i', 1}, {"hit", 'b', 1}}},
        {"refray::procedural::proceduray::ShadowRayPayload", {{"dist", 'f', 1}, {"hit", 'b', 1}}},
        {"refray::procedural::d3d12::RayPayload", {{"color", 'f', 4}, {"recursionDepth", 'u', 1}}},
        {"refray::procedural::d3d12::ShadowRayPayload", {{"hit", 'b', 1}}},
    };
    return layouts;
}


std::string formatWord(uint32_t word, char kind) {
    switch (kind) {
        case 'f': {
            float f;
            std::memcpy(&f, &word, 4);
            return shortestFloat(f);
        }
        case 'i': return std::to_string(int32_t(word));
        case 'b': return word ? "true" : "false";
        default: return std::to_string(word);
    }
}


std::string vec3Text(const vec3& v) {
    return "(" + shortestFloat(v.x) + ", " + shortestFloat(v.y) + ", " + shortestFloat(v.z) + ")";
}

}  // namespace

std::string describePayload(const std::string& typeName, const std::vector<uint8_t>& bytes) {
    std::vector<uint32_t> words(bytes.size() / 4);
    if (!words.empty()) std::memcpy(words.data(), bytes.data(), words.size() * 4);
    std::string out;
    for (const PayloadLayout& layout : payloadLayouts()) {
        if (typeName != layout.typeName) continue;
        size_t w = 0;
        for (const PayloadField& f : layout.fields) {
            if (w + f.components > words.size()) break;
            if (!out.empty()) out += ", ";
            out += f.name;
            out += "=";
            if (f.components > 1) out += "(";
            for (uint32_t c = 0; c < f.components; ++c) {
                if (c) out += ", ";
                out += formatWord(words[w++], f.kind);
            }
            if (f.components > 1) out += ")";
        }
        return out;
    }
    for (size_t i = 0; i < words.size(); ++i) {
        if (i) out += " ";
        out += hexText(words[i]);
    }
    return out;
}

// ---- Text -------------------------------------------------------------------------------------------

namespace {

// The scene's name for a ray type with these TraceRay arguments, if one matches.
std::string rayTypeName(const SceneDesc& scene, const TraceEvent& e) {
    for (const RayTypeDesc& t : scene.rayTypes)
        if (t.rayContribution == e.rayContribution && t.multiplier == e.multiplier && t.missShaderIndex == e.missShaderIndex)
            return t.name;
    return "";
}

std::string instanceText(const SceneDesc& scene, const TraceEvent& e) {
    std::string out = "instance " + std::to_string(e.instanceIndex);
    if (e.instanceIndex < scene.instances.size()) out += " '" + scene.instances[e.instanceIndex].name + "'";
    return out;
}

std::string hitText(const SceneDesc& scene, const TraceEvent& e) {
    return instanceText(scene, e) + " (InstanceID " + std::to_string(e.instanceID) + "), geometry " +
           std::to_string(e.geometryIndex) + ", primitive " + std::to_string(e.primitiveIndex);
}

std::string hitKindText(uint32_t hitKind) {
    if (hitKind == dxr::HIT_KIND_TRIANGLE_FRONT_FACE) return "HIT_KIND_TRIANGLE_FRONT_FACE";
    if (hitKind == dxr::HIT_KIND_TRIANGLE_BACK_FACE) return "HIT_KIND_TRIANGLE_BACK_FACE";
    return std::to_string(hitKind);
}

// "I = R + M×G + C = 0 + 2×0 + 4 = 4", with the raw arguments where the 4-bit mask changed them (IDX-2).
std::string termsText(const dxr::HitGroupIndexTerms& t) {
    std::string out = "I = R + M×G + C = " + std::to_string(t.rayContribution) + " + " + std::to_string(t.multiplier) +
                      "×" + std::to_string(t.geometryIndex) + " + " + std::to_string(t.instanceContribution) + " = " +
                      std::to_string(t.index);
    if (t.rawRayContribution != t.rayContribution || t.rawMultiplier != t.multiplier)
        out += " (TraceRay passed R " + std::to_string(t.rawRayContribution) + ", M " + std::to_string(t.rawMultiplier) +
               "; only the low 4 bits count, IDX-2)";
    return out;
}

struct TextWriter {
    std::ostringstream out;
    void line(uint32_t indent, const std::string& text) { out << std::string(indent * 2, ' ') << text << '\n'; }
};

// One step of a RayQuery's life (emulator/ray_query.h) at `level`: TraceRayInline, each candidate and what the system
// did with it, each Proceed and what it handed the shader, each commit (the shader's decision) and Abort.
void writeQueryEvent(TextWriter& w, const SceneDesc& scene, const RecordedEvent& r, uint32_t level) {
    const TraceEvent& e = r.event;
    const std::string q = "RayQuery #" + std::to_string(e.queryId);
    switch (e.kind) {
        case Kind::QueryInit:
            w.line(level, q + " in " + std::string(dxr::toString(e.stage)) + " shader '" + r.exportName +
                              "': TraceRayInline (no shader table: the owning shader decides for each candidate)");
            w.line(level + 1, "origin " + vec3Text(e.ray.Origin) + "  direction " + vec3Text(e.ray.Direction) + "  TMin " +
                                  shortestFloat(e.ray.TMin) + "  TMax " + shortestFloat(e.ray.TMax));
            w.line(level + 1, "RayFlags (template | TraceRayInline) " + dxr::rayFlagsToString(e.effectiveFlags) +
                                  "  InstanceInclusionMask " + hexText(e.instanceInclusionMask));
            break;
        case Kind::Candidate:
            w.line(level + 1, q + " candidate: " + hitText(scene, e) +
                                  (e.procedural ? ", AABB entered at t = " + shortestFloat(e.t) : ", triangle at t = " + shortestFloat(e.t)));
            break;
        case Kind::Skipped: w.line(level + 2, "skipped by the system: " + r.note); break;
        case Kind::QueryProceed:
            w.line(level, q + " Proceed() = " + r.note +
                              (e.accepted ? " (" + hitText(scene, e) + (e.procedural ? ", box entry t = " : ", t = ") + shortestFloat(e.t) + ")"
                                          : "; CommittedRayT = " + shortestFloat(e.t) +
                                                (e.committed ? "" : " (COMMITTED_NOTHING: TMax)")));
            break;
        case Kind::QueryCommit:
            w.line(level + 1, q + " commit: " + r.note + ": " + hitText(scene, e) + ", CommittedRayT = " + shortestFloat(e.t));
            break;
        case Kind::QueryAbort: w.line(level, q + " Abort(): " + r.note); break;
        default: break;
    }
}

}  // namespace

std::string formatExplanation(const Explanation& x, const SceneDesc& scene) {
    TextWriter w;
    w.line(0, "refray explain: scene '" + x.scene + "', camera '" + x.camera + "', " + std::to_string(x.width) + "x" +
                  std::to_string(x.height) + ", time " + x.time + ", " + x.precision + " shaders");
    if (scene.computeShader.empty())
        w.line(0, "pixel (" + std::to_string(x.x) + ", " + std::to_string(x.y) + ") = DispatchRaysIndex (" +
                      std::to_string(x.x) + ", " + std::to_string(x.y) + ", 0)");
    else
        w.line(0, "pixel (" + std::to_string(x.x) + ", " + std::to_string(x.y) + ") = SV_DispatchThreadID (" +
                      std::to_string(x.x) + ", " + std::to_string(x.y) + ", 0) of a compute dispatch of '" +
                      scene.computeShader + "' (no shader table, no TraceRay: it traces inline)");
    uint32_t rayNumber = 0;
    std::vector<uint32_t> rayStack;  // ray numbers of the TraceRays in flight
    // Per query: the level of its lines, and whether the shader was handed a candidate it has not committed yet.
    std::map<uint32_t, std::pair<uint32_t, bool>> undecided;
    auto closeDecision = [&](uint32_t query) {
        auto it = undecided.find(query);
        if (it == undecided.end() || !it->second.second) return;
        w.line(it->second.first + 1, "RayQuery #" + std::to_string(query) + " the shader's decision: no commit for this candidate");
        it->second.second = false;
    };
    for (const RecordedEvent& r : x.events) {
        const TraceEvent& e = r.event;
        // Levels: a TraceRay of depth d at 3d-2, its details at 3d-1, what it runs at 3d, inside those at 3d+1.
        const uint32_t base = e.depth == 0 ? 0 : 3 * e.depth - 1;
        if (e.queryId != 0) {  // a RayQuery's life, inside the shader that owns it
            const uint32_t level = base + (e.depth == 0 ? 1 : 2);
            if (e.kind != Kind::QueryCommit) closeDecision(e.queryId);
            if (e.kind == Kind::QueryCommit) undecided[e.queryId].second = false;
            writeQueryEvent(w, scene, r, level);
            if (e.kind == Kind::QueryProceed) undecided[e.queryId] = {level, e.accepted};
            continue;
        }
        switch (e.kind) {
            case Kind::ShaderCall: {
                const std::string stage(dxr::toString(e.stage));
                if (e.stage == dxr::ShaderStage::RayGeneration) {
                    w.line(0, stage + " shader '" + r.exportName + "' (ray generation record at " + hexText(e.recordAddress) + ")");
                } else {
                    w.line(base + 1, stage + " shader '" + r.exportName + "' runs" +
                                         (e.stage == dxr::ShaderStage::Compute ? std::string(" (no record)")
                                                                               : " (record " + std::to_string(e.recordIndex) + ")"));
                }
                break;
            }
            case Kind::TraceRay: {
                rayStack.push_back(++rayNumber);
                const std::string type = rayTypeName(scene, e);
                w.line(base - 1, "TraceRay #" + std::to_string(rayNumber) + " (depth " + std::to_string(e.depth) +
                                     (type.empty() ? "" : ", ray type '" + type + "'") + ")");
                w.line(base, "origin " + vec3Text(e.ray.Origin) + "  direction " + vec3Text(e.ray.Direction) + "  TMin " +
                                 shortestFloat(e.ray.TMin) + "  TMax " + shortestFloat(e.ray.TMax));
                std::string flags = "RayFlags " + dxr::rayFlagsToString(e.rayFlags);
                if (e.effectiveFlags != e.rayFlags) flags += " (with the pipeline's: " + dxr::rayFlagsToString(e.effectiveFlags) + ")";
                w.line(base, flags + "  InstanceInclusionMask " + hexText(e.instanceInclusionMask));
                w.line(base, "RayContributionToHitGroupIndex R = " + std::to_string(e.rayContribution) +
                                 ", MultiplierForGeometryContributionToHitGroupIndex M = " + std::to_string(e.multiplier) +
                                 ", MissShaderIndex = " + std::to_string(e.missShaderIndex));
                for (size_t i = 0; i < scene.instances.size(); ++i) {  // INST-4: instances this ray can never see
                    const uint32_t both = scene.instances[i].mask & e.instanceInclusionMask & 0xFF;
                    if (both == 0)
                        w.line(base, "masked out: instance " + std::to_string(i) + " '" + scene.instances[i].name +
                                         "' (InstanceMask " + hexText(scene.instances[i].mask) + " & InstanceInclusionMask & 0xFF = 0, INST-4)");
                }
                w.line(base, "payload in: " + withoutNamespace(r.payloadType) + " {" + describePayload(r.payloadType, r.payload) + "}");
                break;
            }
            case Kind::Candidate:
                w.line(base, "candidate: " + hitText(scene, e) +
                                 (e.procedural ? ", AABB entered at t = " + shortestFloat(e.t) : ", triangle at t = " + shortestFloat(e.t)));
                break;
            case Kind::Skipped: w.line(base + 1, "skipped: " + r.note); break;
            case Kind::RecordLookup: {
                std::string text;
                if (e.hasTerms) {
                    text = "hit-group record: " + termsText(e.terms) + "; address = StartAddress + " + std::to_string(e.stride) +
                           "×" + std::to_string(e.recordIndex) + " = " + hexText(e.recordAddress);
                } else if (r.table == "ray generation record") {
                    text = "ray generation record at " + hexText(e.recordAddress);
                } else {
                    text = r.table + " record " + std::to_string(e.recordIndex);
                    if (r.table == "miss shader table") text += " (MissShaderIndex & 0xFFFF)";
                    text += "; address = StartAddress + " + std::to_string(e.stride) + "×" + std::to_string(e.recordIndex) +
                            " = " + hexText(e.recordAddress);
                }
                if (r.note == "NULL") text += ": NULL (no shader runs, REC-8)";
                else if (r.note == "invalid") text += ": invalid (see the error below)";
                else text += ": '" + r.exportName + "'";
                w.line(base + 1, text);
                break;
            }
            case Kind::ReportHit:
                w.line(base + 2, "ReportHit(THit = " + shortestFloat(e.t) + ", HitKind = " + hitKindText(e.hitKind) + "): " + r.note);
                break;
            case Kind::AnyHit: w.line(base + 2, "any-hit decision: " + r.note); break;
            case Kind::Commit:
                w.line(base + 1, "commit: " + hitText(scene, e) + ", t = " + shortestFloat(e.t) + ", HitKind " + hitKindText(e.hitKind));
                break;
            case Kind::QueryInit:
            case Kind::QueryProceed:
            case Kind::QueryCommit:
            case Kind::QueryAbort: break;  // every query event has a queryId: written above
            case Kind::TraceRayEnd: {
                const uint32_t number = rayStack.empty() ? 0 : rayStack.back();
                if (!rayStack.empty()) rayStack.pop_back();
                w.line(base, "result of TraceRay #" + std::to_string(number) + ": " +
                                 (e.committed ? "hit " + hitText(scene, e) + " at t = " + shortestFloat(e.t) : std::string("miss")) +
                                 (r.note.empty() ? "" : "; " + r.note));
                w.line(base, "payload out: " + withoutNamespace(r.payloadType) + " {" + describePayload(r.payloadType, r.payload) + "}");
                break;
            }
        }
    }
    for (const dxr::Diagnostic& d : x.warnings) w.line(0, d.format());
    if (x.error) {
        w.line(0, "the dispatch stopped at this pixel:");
        w.line(1, x.error->format());
    }
    if (x.pixel)
        w.line(0, "pixel value (RGBA as the shaders wrote it): (" + shortestFloat(x.pixel->r) + ", " + shortestFloat(x.pixel->g) +
                      ", " + shortestFloat(x.pixel->b) + ", " + shortestFloat(x.pixel->a) + ")");
    return w.out.str();
}

// ---- JSON -------------------------------------------------------------------------------------------

namespace {

const char* kindName(Kind k) {
    switch (k) {
        case Kind::ShaderCall: return "shaderCall";
        case Kind::TraceRay: return "traceRay";
        case Kind::Candidate: return "candidate";
        case Kind::Skipped: return "skipped";
        case Kind::RecordLookup: return "recordLookup";
        case Kind::ReportHit: return "reportHit";
        case Kind::AnyHit: return "anyHit";
        case Kind::Commit: return "commit";
        case Kind::TraceRayEnd: return "traceRayEnd";
        case Kind::QueryInit: return "queryInit";
        case Kind::QueryProceed: return "queryProceed";
        case Kind::QueryCommit: return "queryCommit";
        case Kind::QueryAbort: return "queryAbort";
    }
    return "?";
}

std::string jsonNumber(float v) {
    const std::string s = shortestFloat(v);
    return std::isfinite(v) ? s : json::quoted(s);  // JSON has no NaN or infinity
}

std::string jsonVec3(const vec3& v) { return "[" + jsonNumber(v.x) + ", " + jsonNumber(v.y) + ", " + jsonNumber(v.z) + "]"; }

std::string diagnosticJson(const dxr::Diagnostic& d) {
    std::string out = "{\"rule\": " + json::quoted(d.ruleId) + ", \"message\": " + json::quoted(d.message) +
                      ", \"text\": " + json::quoted(d.format()) + "}";
    return out;
}

}  // namespace

std::string explanationJson(const Explanation& x, const SceneDesc& scene) {
    std::ostringstream o;
    o << "{\n  \"format\": \"refray-explain/1\",\n";
    o << "  \"scene\": " << json::quoted(x.scene) << ", \"camera\": " << json::quoted(x.camera) << ", \"time\": " << json::quoted(x.time)
      << ", \"precision\": " << json::quoted(x.precision) << ",\n";
    o << "  \"size\": [" << x.width << ", " << x.height << "], \"pixel\": [" << x.x << ", " << x.y << "],\n";
    if (x.pixel)
        o << "  \"value\": [" << jsonNumber(x.pixel->r) << ", " << jsonNumber(x.pixel->g) << ", " << jsonNumber(x.pixel->b)
          << ", " << jsonNumber(x.pixel->a) << "],\n";
    o << "  \"error\": " << (x.error ? diagnosticJson(*x.error) : "null") << ",\n";
    o << "  \"warnings\": [";
    for (size_t i = 0; i < x.warnings.size(); ++i) o << (i ? ", " : "") << diagnosticJson(x.warnings[i]);
    o << "],\n  \"events\": [\n";
    for (size_t i = 0; i < x.events.size(); ++i) {
        const RecordedEvent& r = x.events[i];
        const TraceEvent& e = r.event;
        o << "    {\"kind\": \"" << kindName(e.kind) << "\", \"depth\": " << e.depth;
        if (e.queryId != 0) o << ", \"query\": " << e.queryId;
        switch (e.kind) {
            case Kind::ShaderCall:
                o << ", \"stage\": " << json::quoted(std::string(dxr::toString(e.stage))) << ", \"export\": " << json::quoted(r.exportName)
                  << ", \"recordIndex\": " << e.recordIndex << ", \"recordAddress\": " << e.recordAddress;
                break;
            case Kind::TraceRay:
            case Kind::TraceRayEnd: {
                const std::string type = rayTypeName(scene, e);
                o << ", \"rayType\": " << (type.empty() ? "null" : json::quoted(type)) << ", \"origin\": " << jsonVec3(e.ray.Origin)
                  << ", \"direction\": " << jsonVec3(e.ray.Direction) << ", \"tMin\": " << jsonNumber(e.ray.TMin)
                  << ", \"tMax\": " << jsonNumber(e.ray.TMax) << ", \"rayFlags\": " << e.rayFlags
                  << ", \"rayFlagNames\": " << json::quoted(dxr::rayFlagsToString(e.rayFlags))
                  << ", \"instanceInclusionMask\": " << e.instanceInclusionMask << ", \"rayContribution\": " << e.rayContribution
                  << ", \"multiplier\": " << e.multiplier << ", \"missShaderIndex\": " << e.missShaderIndex
                  << ", \"payloadType\": " << json::quoted(r.payloadType)
                  << ", \"payload\": " << json::quoted(describePayload(r.payloadType, r.payload));
                if (e.kind == Kind::TraceRayEnd) {
                    o << ", \"hit\": " << (e.committed ? "true" : "false");
                    if (e.committed)
                        o << ", \"instanceIndex\": " << e.instanceIndex << ", \"geometryIndex\": " << e.geometryIndex
                          << ", \"primitiveIndex\": " << e.primitiveIndex << ", \"t\": " << jsonNumber(e.t);
                    if (!r.note.empty()) o << ", \"note\": " << json::quoted(r.note);
                }
                break;
            }
            case Kind::Candidate:
            case Kind::Commit:
            case Kind::ReportHit:
            case Kind::AnyHit:
                o << ", \"instanceIndex\": " << e.instanceIndex << ", \"instanceID\": " << e.instanceID
                  << ", \"geometryIndex\": " << e.geometryIndex << ", \"primitiveIndex\": " << e.primitiveIndex
                  << ", \"t\": " << jsonNumber(e.t);
                if (e.kind == Kind::Candidate) o << ", \"procedural\": " << (e.procedural ? "true" : "false");
                if (e.kind != Kind::Candidate) o << ", \"hitKind\": " << e.hitKind;
                if (!r.note.empty()) o << ", \"note\": " << json::quoted(r.note);
                break;
            case Kind::Skipped: o << ", \"note\": " << json::quoted(r.note); break;
            case Kind::QueryInit:
                o << ", \"origin\": " << jsonVec3(e.ray.Origin) << ", \"direction\": " << jsonVec3(e.ray.Direction)
                  << ", \"tMin\": " << jsonNumber(e.ray.TMin) << ", \"tMax\": " << jsonNumber(e.ray.TMax)
                  << ", \"rayFlags\": " << e.rayFlags << ", \"effectiveFlags\": " << e.effectiveFlags
                  << ", \"effectiveFlagNames\": " << json::quoted(dxr::rayFlagsToString(e.effectiveFlags))
                  << ", \"instanceInclusionMask\": " << e.instanceInclusionMask;
                break;
            case Kind::QueryProceed:
                o << ", \"result\": " << (e.accepted ? "true" : "false") << ", \"t\": " << jsonNumber(e.t);
                if (e.accepted)
                    o << ", \"candidateType\": " << json::quoted(e.procedural ? "CANDIDATE_PROCEDURAL_PRIMITIVE" : "CANDIDATE_NON_OPAQUE_TRIANGLE")
                      << ", \"instanceIndex\": " << e.instanceIndex << ", \"instanceID\": " << e.instanceID
                      << ", \"geometryIndex\": " << e.geometryIndex << ", \"primitiveIndex\": " << e.primitiveIndex;
                o << ", \"note\": " << json::quoted(r.note);
                break;
            case Kind::QueryCommit:
                o << ", \"instanceIndex\": " << e.instanceIndex << ", \"instanceID\": " << e.instanceID
                  << ", \"geometryIndex\": " << e.geometryIndex << ", \"primitiveIndex\": " << e.primitiveIndex
                  << ", \"procedural\": " << (e.procedural ? "true" : "false") << ", \"t\": " << jsonNumber(e.t)
                  << ", \"note\": " << json::quoted(r.note);
                break;
            case Kind::QueryAbort: o << ", \"committed\": " << (e.committed ? "true" : "false") << ", \"t\": " << jsonNumber(e.t); break;
            case Kind::RecordLookup:
                o << ", \"table\": " << json::quoted(r.table) << ", \"recordIndex\": " << e.recordIndex
                  << ", \"recordAddress\": " << e.recordAddress << ", \"stride\": " << e.stride
                  << ", \"entry\": " << (r.note.empty() ? json::quoted(r.exportName) : "null")
                  << ", \"status\": " << json::quoted(r.note.empty() ? "ok" : r.note);
                if (e.hasTerms)
                    o << ", \"R\": " << e.terms.rayContribution << ", \"M\": " << e.terms.multiplier << ", \"G\": " << e.terms.geometryIndex
                      << ", \"C\": " << e.terms.instanceContribution << ", \"I\": " << e.terms.index;
                break;
        }
        o << "}" << (i + 1 < x.events.size() ? "," : "") << "\n";
    }
    o << "  ]\n}\n";
    return o.str();
}

}  // namespace refray::scenes
