#include "verify/discrimination.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

#include "core/error.h"
#include "core/image.h"
#include "core/json.h"
#include "core/json_writer.h"
#include "core/strings.h"
#include "scenes/knobs.h"
#include "scenes/scene.h"
#include "scenes/scene_loader.h"
#include "verify/golden.h"

namespace refray::scenes {

namespace fs = std::filesystem;

namespace {

// The correct candidates: seeds and orders past those the envelope was made from (seeds 1..K, orders 1..4).
constexpr uint32_t kFirstUnseenSeed = 9, kLastUnseenSeed = 12;
constexpr uint32_t kFirstUnseenOrder = 5, kLastUnseenOrder = 8;

std::vector<DiscriminationCandidate> makeCandidates() {
    std::vector<DiscriminationCandidate> c;
    using K = CandidateKind;
    for (uint32_t seed = kFirstUnseenSeed; seed <= kLastUnseenSeed; ++seed)
        c.push_back({"perturbed-seed-" + std::to_string(seed), K::Correct, "a legal GPU the envelope has not seen",
                     "--perturb " + std::to_string(seed) + " (" + procedural::describe(goldenPerturbation(seed)) + ")"});
    c.push_back({"double", K::Correct, "the shaders in double precision", "--precision double"});
    for (uint32_t order = kFirstUnseenOrder; order <= kLastUnseenOrder; ++order)
        c.push_back({"order-seed-" + std::to_string(order), K::Correct,
                     "another legal order of intersection-shader calls (GEN-3)",
                     "--order adversarial --seed " + std::to_string(order)});
    c.push_back({"fma-contraction", K::Correct,
                 "refray built with fused multiply-add: the compiler contracts a*b+c wherever it likes, as GPU compilers do",
                 "the refray-fma binary (shader libraries compiled with -mfma -ffp-contract=fast)"});
    c.push_back({"lavapipe", K::Correct,
                 "Mesa's lavapipe (a CPU Vulkan driver, not a GPU) running refray's Vulkan back end and GLSL ports: a "
                 "second implementation of traversal and of every shader",
                 "refray render --device vulkan --vulkan-device llvmpipe"});

    // Mutants: shader constants a port gets wrong (knobs).
    const std::pair<const char*, const char*> knobs[] = {
        {"steps=0.5", "every march's step limit halved"},
        {"threshold=2", "every march's hit threshold doubled"},
        {"threshold=10", "every march's hit threshold ten times too large"},
        {"mandelbulb-iterations=3", "the Mandelbulb's distance estimator iterates 3 times, not 4"},
        {"mandelbulb-iterations=5", "the Mandelbulb's distance estimator iterates 5 times, not 4"},
        {"julia-iterations=150", "the Julia distance estimator iterates 150 times, not 200"},
        {"julia-iterations=100", "the Julia distance estimator iterates 100 times, not 200"},
        {"normal-epsilon=2", "the normal estimation's offset doubled"},
        {"normal-epsilon=10", "the normal estimation's offset ten times too large"},
        {"metaball-steps=64", "the metaballs' march samples 64 times, not 128"},
        {"recursion-depth=2", "one reflection bounce lost (MAX_RAY_RECURSION_DEPTH 2, not 3)"},
        {"recursion-depth=1", "reflections lost (MAX_RAY_RECURSION_DEPTH 1)"},
    };
    for (const auto& [assignment, what] : knobs) {
        std::string name = assignment;
        std::replace(name.begin(), name.end(), '=', '-');
        c.push_back({name, K::Mutant, what, std::string("--knob ") + assignment});
    }
    // Mutants: scene data a back end uploads wrong (patches of the scene file).
    c.push_back({"diffuse-2pc", K::Mutant, "every material's diffuse coefficient 2 % low", "scene: diffuseCoef x 0.98"});
    c.push_back({"specular-3pc", K::Mutant, "every material's specular coefficient 3 % high", "scene: specularCoef x 1.03"});
    c.push_back({"specular-power-one-material", K::Mutant,
                 "one material's specular power one higher (the lowest one: D3D12's cog 2 -> 3)",
                 "scene: the first material of the lowest specularPower, specularPower + 1"});
    c.push_back({"albedo-1pc", K::Mutant, "every material's albedo 1 % low", "scene: albedo.rgb x 0.99"});
    c.push_back({"reflectance-3pc", K::Mutant, "every material's reflectance 3 % low", "scene: reflectanceCoef x 0.97"});
    c.push_back({"ambient-2pc", K::Mutant, "the ambient light 2 % low", "scene: light.ambientColor.rgb x 0.98"});
    c.push_back({"light-y-flipped", K::Mutant, "the light's y negated (a y-up / y-down convention mixed up)",
                 "scene: light.position.y x -1"});
    c.push_back({"shadows-lost", K::Mutant, "shadow rays traced with instance mask 0: no shadows",
                 "scene: rayTypes[1].traceRay.instanceInclusionMask = 0"});
    c.push_back({"record-off-by-one", K::Mutant,
                 "radiance rays index the hit-group table with R = 1: the shadow hit groups (IDX-3)",
                 "scene: rayTypes[0].traceRay.rayContribution = 1"});
    c.push_back({"multiplier-one", K::Mutant, "M = 1 on both ray types: records of other geometries (IDX-4)",
                 "scene: rayTypes[*].traceRay.multiplier = 1"});
    c.push_back({"instance-mask-zero", K::Mutant,
                 "the last instance's InstanceMask left 0 in its instance desc: it disappears",
                 "scene: instances[last].mask = 0"});
    c.push_back({"transform-transposed", K::Mutant,
                 "instance 1's 3x4 transform uploaded transposed: rotation inverted, translation lost",
                 "scene: instances[1].transform transposed"});
    // Mutants: RayQuery bugs (issue 26), each played by variant exports of the inline-tracing shaders that the patch
    // puts in the scene (procedural/d3d12/d3d12_shaders.cpp, InlineVariant). A scene without inline tracing keeps its
    // exports: the mutant renders the nominal image there.
    c.push_back({"rq-procedural-ignored", K::Mutant,
                 "inline tracing that never intersects procedural candidates (a Proceed loop written for triangles, or a "
                 "back end that drops CANDIDATE_PROCEDURAL_PRIMITIVE): procedural geometry invisible to RayQuery",
                 "scene: inline-tracing exports -> their _IgnoreProcedural variants"});
    c.push_back({"rq-commit-outside-range", K::Mutant,
                 "the shader-side range check dropped: each procedural candidate intersected over the whole ray line and "
                 "its t committed unchecked, outside [RayTMin, CommittedRayT] (RQ-22)",
                 "scene: inline-tracing exports -> their _NoRangeCheck variants"});
    c.push_back({"rq-committed-t-is-tmax", K::Mutant,
                 "CommittedRayT() returns the ray's TMax after a commit (the wrong committed t read back)",
                 "scene: inline-tracing exports -> their _CommittedTIsTMax variants"});
    // Mutants: the camera and the clock.
    c.push_back({"time-one-frame-late", K::Mutant, "the animation one 60 Hz frame late", "--time t + 1/60"});
    // Mutants: the output stage (the render is right, the image written is not).
    c.push_back({"shifted-one-pixel", K::Mutant, "DispatchRaysIndex off by one: the image one pixel to the right",
                 "image: column x takes column x-1"});
    c.push_back({"flipped-vertically", K::Mutant, "the image upside down (a Vulkan viewport's y)", "image: rows reversed"});
    c.push_back({"bgr-swapped", K::Mutant, "red and blue swapped (a BGRA target read as RGBA)", "image: R <-> B"});
    c.push_back({"srgb-encoded", K::Mutant, "an _SRGB render target: the sRGB curve applied on store",
                 "image: linear -> sRGB"});
    return c;
}

std::string number(double x) {
    char text[40];
    std::snprintf(text, sizeof text, "%.9g", x);
    return text;
}

// A JSON Patch (as text) that makes the scene file `scene` into mutant `name`.
std::string scenePatch(const json::Value& scene, const std::string& name) {
    std::vector<std::string> ops;
    const auto replace = [&](const std::string& path, const std::string& value) {
        ops.push_back("{\"op\": \"replace\", \"path\": \"" + path + "\", \"value\": " + value + "}");
    };
    const auto scaleMaterials = [&](const std::string& field, double factor, bool rgb) {
        const json::Value* values = scene.find("values");
        REFRAY_CHECK(values && values->isObject(), "the scene has no 'values' to patch");
        for (const auto& member : values->asObject()) {
            const json::Value* v = member.value.find(field);
            if (!v) continue;
            const std::string path = "/values/" + member.key + "/" + field;
            if (!rgb) {
                replace(path, number(v->asNumber() * factor));
                continue;
            }
            const auto& a = v->asArray();
            std::string text = "[";
            for (size_t i = 0; i < a.size(); ++i)
                text += (i ? ", " : "") + number(i < 3 ? a[i].asNumber() * factor : a[i].asNumber());
            replace(path, text + "]");
        }
    };
    const auto traceRay = [&](size_t rayType, const std::string& object) {
        ops.push_back("{\"op\": \"add\", \"path\": \"/rayTypes/" + std::to_string(rayType) + "/traceRay\", \"value\": " +
                      object + "}");
    };
    // The inline-tracing exports (closest hits ending in _InlineShadow, the compute shader) -> their variants.
    const auto inlineVariant = [&](const std::string& suffix) {
        if (const json::Value* groups = scene.find("hitGroups"))
            for (size_t i = 0; i < groups->asArray().size(); ++i)
                if (const json::Value* ch = groups->asArray()[i].find("closestHit")) {
                    const std::string& e = ch->asString();
                    const std::string tail = "_InlineShadow";
                    if (e.size() >= tail.size() && e.compare(e.size() - tail.size(), tail.size(), tail) == 0)
                        replace("/hitGroups/" + std::to_string(i) + "/closestHit", json::quoted(e + suffix));
                }
        if (const json::Value* pipeline = scene.find("pipeline"))
            if (const json::Value* cs = pipeline->find("compute"))
                replace("/pipeline/compute", json::quoted(cs->asString() + suffix));
    };
    if (name == "rq-procedural-ignored") inlineVariant("_IgnoreProcedural");
    else if (name == "rq-commit-outside-range") inlineVariant("_NoRangeCheck");
    else if (name == "rq-committed-t-is-tmax") inlineVariant("_CommittedTIsTMax");
    else if (name == "diffuse-2pc") scaleMaterials("diffuseCoef", 0.98, false);
    else if (name == "specular-3pc") scaleMaterials("specularCoef", 1.03, false);
    else if (name == "albedo-1pc") scaleMaterials("albedo", 0.99, true);
    else if (name == "reflectance-3pc") scaleMaterials("reflectanceCoef", 0.97, false);
    else if (name == "specular-power-one-material") {
        const json::Value* values = scene.find("values");
        REFRAY_CHECK(values && values->isObject(), "the scene has no 'values' to patch");
        std::string lowest;
        double power = 0;
        for (const auto& member : values->asObject())
            if (const json::Value* v = member.value.find("specularPower"); v && (lowest.empty() || v->asNumber() < power)) {
                lowest = member.key;
                power = v->asNumber();
            }
        REFRAY_CHECK(!lowest.empty(), "the scene has no material with a specularPower to patch");
        replace("/values/" + lowest + "/specularPower", number(power + 1));
    }
    else if (name == "ambient-2pc" || name == "light-y-flipped") {
        const json::Value* light = scene.find("light");
        REFRAY_CHECK(light, "the scene has no 'light' to patch");
        const bool ambient = name == "ambient-2pc";
        const auto& a = light->find(ambient ? "ambientColor" : "position")->asArray();
        std::string text = "[";
        for (size_t i = 0; i < a.size(); ++i) {
            const double x = a[i].asNumber();
            text += (i ? ", " : "") + number(ambient ? (i < 3 ? x * 0.98 : x) : (i == 1 ? -x : x));
        }
        replace(ambient ? "/light/ambientColor" : "/light/position", text + "]");
    } else if (name == "shadows-lost") traceRay(1, "{\"instanceInclusionMask\": 0}");
    else if (name == "record-off-by-one") traceRay(0, "{\"rayContribution\": 1}");
    else if (name == "multiplier-one") {
        traceRay(0, "{\"multiplier\": 1}");
        traceRay(1, "{\"multiplier\": 1}");
    } else if (name == "instance-mask-zero") {
        replace("/instances/" + std::to_string(scene.find("instances")->asArray().size() - 1) + "/mask", "0");
    }
    else if (name == "transform-transposed") {
        // The row-vector 4x4 as the scene file gives it, or scale and translation: transposing the 3x4 that DXR
        // reads puts the rotation's transpose in place and the translation where the GPU ignores it.
        const json::Value& transform = *scene.find("instances")->asArray().at(1).find("transform");
        std::string text;
        if (const json::Value* m = transform.find("rowVectorMatrix")) {
            text = "{\"rowVectorMatrix\": [";
            for (size_t r = 0; r < 4; ++r) {
                text += r ? ", [" : "[";
                for (size_t c = 0; c < 4; ++c) {
                    const double x = r < 3 && c < 3 ? m->asArray()[c].asArray()[r].asNumber() : (r == c ? 1.0 : 0.0);
                    text += (c ? ", " : "") + number(x);
                }
                text += "]";
            }
            text += "]}";
        } else {
            text = "{}";
            if (const json::Value* scale = transform.find("scale")) {
                const auto& s = scale->asArray();
                text = "{\"scale\": [" + number(s[0].asNumber()) + ", " + number(s[1].asNumber()) + ", " +
                       number(s[2].asNumber()) + "]}";
            }
        }
        replace("/instances/1/transform", text);
    } else
        REFRAY_CHECK(false, "no scene patch for candidate '" << name << "'");
    std::string patch = "[";
    for (size_t i = 0; i < ops.size(); ++i) patch += (i ? ",\n  " : "") + ops[i];
    return patch + "]";
}

// The scene file with the patch applied, as a lesson based on it (scenes/scene_loader.h).
std::unique_ptr<Scene> patchedScene(const fs::path& sceneFile, const std::string& name) {
    const std::string patch = scenePatch(json::parseFile(sceneFile), name);
    const std::string lesson = "{\"format\": \"refray-lesson/1\", \"name\": \"mutant-" + name +
                               "\", \"base\": \"" + sceneFile.filename().string() + "\", \"title\": \"mutant " +
                               name + "\", \"patch\": " + patch + "}";
    return std::make_unique<Scene>(
        parseScene(lesson, (sceneFile.parent_path() / ("mutant-" + name + ".json")).string()));
}

Image mutateImage(const Image& in, const std::string& name) {
    Image out = in;
    const uint32_t w = in.width(), h = in.height();
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            vec4& p = out.at(x, y);
            if (name == "shifted-one-pixel") p = in.at(x == 0 ? 0 : x - 1, y);
            else if (name == "flipped-vertically") p = in.at(x, h - 1 - y);
            else if (name == "bgr-swapped") std::swap(p.r, p.b);
            else if (name == "srgb-encoded")
                for (int c = 0; c < 3; ++c) {
                    const float v = std::clamp(p[c], 0.0f, 1.0f);
                    p[c] = v <= 0.0031308f ? 12.92f * v : 1.055f * std::pow(v, 1.0f / 2.4f) - 0.055f;
                }
        }
    return out;
}

bool startsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

// Another refray process renders the golden's settings into a temporary EXR: refray-fma, or refray on lavapipe.
Image renderByProcess(const DiscriminationOptions& o, const GoldenEntry& e, DiscriminationRow& row,
                      const fs::path& binary, const std::string& extraArguments, const std::string& label,
                      const std::string& whenMissing) {
    std::string& error = row.error;
    if (binary.empty()) {
        row.unavailable = true;
        error = whenMissing;
        return {};
    }
    const fs::path out = fs::temp_directory_path() / (label + "-" + std::to_string(::getpid()) + "-" + e.name + ".exr");
    const fs::path log = fs::path(out).replace_extension(".log");
    const std::string command = shellQuoted(binary.string()) + " render " +
                                shellQuoted((o.repositoryRoot / e.scene).string()) + " --camera " +
                                shellQuoted(e.camera) + " --time " + shellQuoted(e.time) + " --size " +
                                std::to_string(e.width) + "x" + std::to_string(e.height) + " --precision " +
                                e.precision + " --threads " + std::to_string(o.threads) + extraArguments + " -o " +
                                shellQuoted(out.string()) + " > " + shellQuoted(log.string()) + " 2>&1";
    const int status = std::system(command.c_str());
    std::string said;
    {
        std::ifstream in(log);
        std::getline(in, said, '\0');
    }
    fs::remove(log);
    if (status != 0) {
        // A missing Vulkan device is the machine's, not the candidate's: reported as not run.
        if (said.find("no Vulkan") != std::string::npos) row.unavailable = true;
        while (!said.empty() && (said.back() == '\n' || said.back() == ' ')) said.pop_back();
        error = label + " exited with status " + std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : status) +
                (said.empty() ? "" : ": " + said);
        fs::remove(out);
        return {};
    }
    Image image = readImage(out.string());
    fs::remove(out);
    return image;
}

}  // namespace

const std::vector<DiscriminationCandidate>& discriminationCandidates() {
    static const std::vector<DiscriminationCandidate> all = makeCandidates();
    return all;
}

std::vector<DiscriminationRow> runDiscrimination(const DiscriminationOptions& o) {
    const GoldenSet set = readGoldenManifest(o.goldenDirectory / "goldens.json");
    for (const std::string& name : o.only)
        REFRAY_CHECK(std::any_of(discriminationCandidates().begin(), discriminationCandidates().end(),
                                 [&](const DiscriminationCandidate& c) { return c.name == name; }),
                     "no discrimination candidate named '" << name << "'");
    std::vector<DiscriminationRow> rows;
    for (const std::string& name : o.goldens)
        REFRAY_CHECK(std::any_of(set.entries.begin(), set.entries.end(), [&](const GoldenEntry& e) { return e.name == name; }),
                     "no golden named '" << name << "' in " << (o.goldenDirectory / "goldens.json").string());
    for (const GoldenEntry& entry : set.entries) {
        if (!o.goldens.empty() && std::find(o.goldens.begin(), o.goldens.end(), entry.name) == o.goldens.end()) continue;
        const Envelope envelope = readEnvelope((o.goldenDirectory / entry.envelope).string());
        const fs::path sceneFile = o.repositoryRoot / entry.scene;
        std::unique_ptr<Scene> scene = loadScene(sceneFile);
        const RenderSettings base = goldenSettings(entry, o.threads);
        for (const DiscriminationCandidate& c : discriminationCandidates()) {
            if (!o.only.empty() && std::find(o.only.begin(), o.only.end(), c.name) == o.only.end()) continue;
            DiscriminationRow row;
            row.golden = entry.name;
            row.candidate = c;
            const auto start = std::chrono::steady_clock::now();
            Image image;
            try {
                RenderSettings s = base;
                const std::string& n = c.name;
                if (startsWith(n, "perturbed-seed-")) {
                    s.perturbation = goldenPerturbation(uint32_t(std::stoul(n.substr(15))));
                    image = renderEnvelopePart(*scene, {n, s});
                    if (image.metadata.at("golden_part_seed") != n.substr(15))
                        row.note = "seed " + n.substr(15) + " reaches undefined behaviour; seed " +
                                   image.metadata.at("golden_part_seed") + " instead";
                } else if (n == "double") {
                    s.precision = procedural::Precision::Double;
                    image = scene->render(s).image;
                } else if (startsWith(n, "order-seed-")) {
                    s.order = dxr::TraversalOrder::Adversarial;
                    s.adversarialSeed = std::stoul(n.substr(11));
                    image = scene->render(s).image;
                } else if (n == "fma-contraction") {
                    image = renderByProcess(o, entry, row, o.fusedRefray, "", "refray-fma",
                                            "no refray-fma binary given (--fma-refray, or build the refray-fma target)");
                } else if (n == "lavapipe") {
                    const char* device = std::getenv("REFRAY_LAVAPIPE_DEVICE");
                    image = renderByProcess(o, entry, row, o.vulkanRefray,
                                            " --device vulkan --vulkan-device " +
                                                shellQuoted(device && *device ? device : "llvmpipe"),
                                            "lavapipe",
                                            "no refray with the Vulkan back end given (--vulkan-refray; this refray "
                                            "was built without it)");
                } else if (startsWith(c.how, "--knob ")) {
                    applyKnobAssignment(s, c.how.substr(7));
                    image = scene->render(s).image;
                } else if (n == "time-one-frame-late") {
                    s.time = s.time.value_or(0.0f) + 1.0f / 60.0f;
                    image = scene->render(s).image;
                } else if (startsWith(c.how, "scene: ")) {
                    image = patchedScene(sceneFile, n)->render(s).image;
                } else if (startsWith(c.how, "image: ")) {
                    image = mutateImage(scene->render(s).image, n);
                } else {
                    REFRAY_CHECK(false, "candidate '" << n << "' has no recipe");
                }
            } catch (const std::exception& e) {
                row.error = e.what();
            }
            row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
            if (!image.empty()) {
                row.ran = true;
                row.judgement = judgeEnvelope(envelope, image, {});
                row.judgement.heatMap = Image();
                row.judgement.outside.clear();
                if (image.width() == envelope.width() && image.height() == envelope.height())
                    for (size_t i = 0; i < image.pixels().size(); ++i) {
                        bool changed = false;
                        for (int ch = 0; ch < kEnvelopeChannels; ++ch) {
                            const int d = int(floatToUnorm8(image.pixels()[i][ch])) -
                                          int(floatToUnorm8(envelope.nominal.pixels()[i][ch]));
                            changed = changed || d > 1 || d < -1 || !std::isfinite(image.pixels()[i][ch]);
                        }
                        if (!changed) continue;
                        if (envelope.orderDependent[i]) ++row.changedOrder;
                        else if (envelope.pixelClass[i] == PixelClass::Sensitive) ++row.changedSensitive;
                        else ++row.changedStable;
                    }
            }
            if (o.onRow) o.onRow(row);
            rows.push_back(std::move(row));
        }
    }
    return rows;
}

std::string outcomeName(const DiscriminationRow& row) {
    if (!row.ran) return row.unavailable ? "not run" : "render error";
    switch (row.judgement.verdict) {
        case CompareVerdict::Pass: return "pass";
        case CompareVerdict::Warn: return "WARNING";
        case CompareVerdict::Fail: return "FAILURE";
        case CompareVerdict::Mismatch: return "MISMATCH";
    }
    return "?";
}

bool outcomeAsExpected(const DiscriminationRow& row) {
    if (row.candidate.kind == CandidateKind::Correct) return row.ran && row.judgement.verdict != CompareVerdict::Fail;
    return !row.ran ? outcomeName(row) == "render error" : row.judgement.verdict == CompareVerdict::Fail;
}

namespace {

std::string pValue(double p) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.2g", p);
    return buf;
}

// Why a mutant that passes cannot be caught by this golden (or by any image test).
std::string missReason(const DiscriminationRow& r) {
    if (r.changedStable + r.changedSensitive + r.changedOrder == 0)
        return "changes no pixel by more than one step at this setting: invisible to any image test";
    const std::string sensitive = std::to_string(r.judgement.sensitiveOutside) + " sensitive pixels outside (budget " +
                                  std::to_string(r.judgement.sensitiveBudget) + ")";
    const std::string regional = r.judgement.regional.available
                                     ? "; no region and direction stands out (smallest adjusted p " +
                                           pValue(r.judgement.regional.smallestAdjustedP) + ")"
                                     : "";
    if (r.changedStable == 0)
        return "moves no stable pixel, and " + sensitive + ": within what correct renders do" + regional;
    return "moves " + std::to_string(r.changedStable) + " stable pixels, within the " +
           std::to_string(r.judgement.stableBudget) + " that correct renders may move, and " + sensitive + regional;
}

// Whether only the regional count test fails the row (the whole-image counts pass it).
bool regionalOnly(const DiscriminationRow& r) {
    const EnvelopeJudgement& j = r.judgement;
    return r.ran && j.regional.failed() && j.nonFinite == 0 && j.stableOutside <= j.stableBudget &&
           j.sensitiveOutside <= j.sensitiveBudget;
}

}  // namespace

std::string discriminationMarkdown(const std::vector<DiscriminationRow>& rows) {
    std::ostringstream md;
    std::map<std::string, std::map<std::string, const DiscriminationRow*>> table;  // candidate -> golden -> row
    std::vector<std::string> goldens;
    for (const DiscriminationRow& r : rows) {
        table[r.candidate.name][r.golden] = &r;
        if (std::find(goldens.begin(), goldens.end(), r.golden) == goldens.end()) goldens.push_back(r.golden);
    }
    uint64_t correct = 0, falseAlarms = 0, mutants = 0, caught = 0, warned = 0, missed = 0, invisible = 0;
    uint64_t caughtRegionally = 0;
    const DiscriminationRow* closest = nullptr;  // the correct row of the smallest regional p
    for (const DiscriminationRow& r : rows) {
        if (r.candidate.kind == CandidateKind::Correct) {
            if (!r.ran) continue;
            ++correct;
            falseAlarms += r.judgement.verdict == CompareVerdict::Fail;
            // The closest by the unadjusted p of its most extreme region (the adjusted one is 1 for most).
            if (r.judgement.regional.available && r.judgement.regional.closest.candidate > 0 &&
                (!closest || r.judgement.regional.closest.p < closest->judgement.regional.closest.p))
                closest = &r;
            continue;
        }
        ++mutants;
        caughtRegionally += regionalOnly(r);
        if (outcomeAsExpected(r)) ++caught;
        else if (r.changedStable + r.changedSensitive + r.changedOrder == 0) ++invisible;
        else if (r.judgement.verdict == CompareVerdict::Warn) ++warned;
        else ++missed;
    }
    md << "| | judged | outcome |\n|---|---|---|\n";
    md << "| correct candidates | " << correct << " | " << falseAlarms << " false alarms |\n";
    md << "| mutants | " << mutants << " | " << caught << " caught, " << warned << " only warned, " << missed
       << " missed, " << invisible << " invisible (no pixel changed by more than one step) |\n\n";
    md << "Of the catches, " << caughtRegionally
       << " by the regional count test alone (the whole-image counts pass them)";
    if (closest)
        md << "; the correct judgement closest to failing it: `" << closest->candidate.name << "` on "
           << closest->golden << ", p " << pValue(closest->judgement.regional.closest.p) << " over "
           << closest->judgement.regional.tests << " tests, adjusted "
           << pValue(closest->judgement.regional.smallestAdjustedP) << " (FAILURE below "
           << pValue(closest->judgement.regional.falseAlarm) << ")";
    md << ".\n\n";

    md << "Each cell: the verdict, then stable pixels moved / the stable budget, sensitive pixels outside / their "
          "budget, and the regional count test's smallest adjusted p (bold where it fails).\n\n| candidate | kind |";
    for (const std::string& g : goldens) md << " " << g << " |";
    md << "\n|---|---|";
    for (size_t i = 0; i < goldens.size(); ++i) md << "---|";
    md << "\n";
    for (const DiscriminationCandidate& c : discriminationCandidates()) {
        const auto found = table.find(c.name);
        if (found == table.end()) continue;
        md << "| `" << c.name << "` | " << (c.kind == CandidateKind::Correct ? "correct" : "mutant") << " |";
        for (const std::string& g : goldens) {
            const auto cell = found->second.find(g);
            if (cell == found->second.end()) {
                md << " - |";
                continue;
            }
            const DiscriminationRow& r = *cell->second;
            const std::string outcome = outcomeName(r);
            md << " " << (outcomeAsExpected(r) || c.kind == CandidateKind::Correct ? outcome : "**" + outcome + "**");
            if (r.ran)
                md << " " << r.judgement.stableOutside << "/" << r.judgement.stableBudget << ", "
                   << r.judgement.sensitiveOutside << "/" << r.judgement.sensitiveBudget;
            if (r.ran && r.judgement.regional.available) {
                const std::string p = "p " + pValue(r.judgement.regional.smallestAdjustedP);
                md << ", " << (r.judgement.regional.failed() ? "**" + p + "**" : p);
            }
            md << " |";
        }
        md << "\n";
    }
    md << "\nWhat each candidate is:\n\n| candidate | what | how |\n|---|---|---|\n";
    for (const DiscriminationCandidate& c : discriminationCandidates())
        if (table.contains(c.name)) md << "| `" << c.name << "` | " << c.what << " | " << c.how << " |\n";

    std::ostringstream misses;
    for (const DiscriminationRow& r : rows) {
        if (outcomeAsExpected(r)) continue;
        misses << "| `" << r.candidate.name << "` | " << r.golden << " | " << outcomeName(r) << " | "
               << (r.candidate.kind == CandidateKind::Correct ? "false alarm" : missReason(r)) << " |\n";
    }
    if (!misses.str().empty())
        md << "\nNot as a golden should (false alarms and mutants that pass):\n\n| candidate | golden | outcome | why "
              "|\n|---|---|---|---|\n"
           << misses.str();
    return md.str();
}

}  // namespace refray::scenes
