#include "scenes/scene.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <functional>
#include <map>
#include <set>

#include "core/error.h"
#include "core/strings.h"
#include "scenes/effects.h"
#include "scenes/knobs.h"
#include "scenes/scene_loader.h"

namespace refray::scenes {

using namespace refray::dxr;
using procedural::DMat4;
using procedural::multiply;
using procedural::rowVectorForm;
using procedural::toFloat4x4;
using procedural::Float4x4;
using procedural::Precision;

namespace {

// S·R·Tr of an element of a primitiveTransforms buffer and its inverse Tr⁻¹·Rᵀ·S⁻¹, in double.
std::pair<Float4x4, Float4x4> primitiveTransform(const PrimitiveTransformDesc& p, double time) {
    const double theta = p.spinYPerSecond * time;
    const double c = std::cos(theta), s = std::sin(theta);
    const DMat4 R = {{{c, 0, -s, 0}, {0, 1, 0, 0}, {s, 0, c, 0}, {0, 0, 0, 1}}};
    const DMat4 Rt = {{{c, 0, s, 0}, {0, 1, 0, 0}, {-s, 0, c, 0}, {0, 0, 0, 1}}};
    DMat4 S{}, Si{}, T{}, Ti{};
    for (int k = 0; k < 4; ++k) S[size_t(k)][size_t(k)] = Si[size_t(k)][size_t(k)] = T[size_t(k)][size_t(k)] = Ti[size_t(k)][size_t(k)] = 1;
    for (int k = 0; k < 3; ++k) {
        S[size_t(k)][size_t(k)] = p.scale[k];
        Si[size_t(k)][size_t(k)] = 1.0 / double(p.scale[k]);
        T[3][size_t(k)] = p.centre[k];
        Ti[3][size_t(k)] = -double(p.centre[k]);
    }
    return {toFloat4x4(multiply(multiply(S, R), T)), toFloat4x4(multiply(multiply(Ti, Rt), Si))};
}

// A shader that writes NaN or Inf into the render target breaks no DXR rule, but the pixel is lost (an
// R8G8B8A8_UNORM target stores 0): a warning (GEN-4) with the count and the first such launch index, in row order.
void reportNonFinitePixels(const Image& target, const RenderSettings& settings, DiagnosticLog& log) {
    uint32_t x0 = 0, y0 = 0, x1 = target.width(), y1 = target.height();
    if (settings.region) {
        x0 = settings.region->x, y0 = settings.region->y;
        x1 = x0 + settings.region->width, y1 = y0 + settings.region->height;
    }
    uint64_t count = 0;
    uvec2 first(0u);
    for (uint32_t y = y0; y < y1; ++y)
        for (uint32_t x = x0; x < x1; ++x) {
            const vec4& p = target.at(x, y);
            if (std::isfinite(p.r) && std::isfinite(p.g) && std::isfinite(p.b) && std::isfinite(p.a)) continue;
            if (count++ == 0) first = uvec2(x, y);
        }
    if (count == 0) return;
    const vec4& p = target.at(first.x, first.y);
    std::string where = std::to_string(first.x);
    where += ",";
    where += std::to_string(first.y);
    std::string value = "(";
    for (int c = 0; c < 4; ++c) {
        if (c) value += ", ";
        value += shortestFloat(p[c]);
    }
    value += ")";
    log.add(warning("GEN-4", "the shaders wrote NaN or Inf to the render target; an R8G8B8A8_UNORM target stores 0 "
                             "there (refray explain --pixel shows the rays of the first)")
                .value("pixels", count)
                .value("first launch index", where)
                .value("its value", value));
}

uint32_t sampleGridSize(uint32_t spp) {
    const uint32_t k = uint32_t(std::lround(std::sqrt(double(spp))));
    REFRAY_CHECK(spp >= 1 && k * k == spp && k <= 16,
                 "--spp must be a square number from 1 to 256 (1, 4, 9, 16, ...): the samples are a k x k grid of "
                 "pixel centres of a k-times larger dispatch; got "
                     << spp);
    return k;
}

// The dispatch's samples per pixel in each dimension: k for a k x k grid, 1 for a library whose shaders draw the
// samples themselves (ShaderLibraryBinding::samplesInShader).
uint32_t sampleGridSize(uint32_t spp, const ShaderLibraryBinding& binding) {
    if (!binding.samplesInShader) return sampleGridSize(spp);
    REFRAY_CHECK(spp >= 1 && spp <= binding.maxSamplesPerPixel,
                 "--spp for library '" << binding.name << "' is the number of random paths per pixel that its ray "
                                       << "generation shader averages (samplesPerPixel), 1 to "
                                       << binding.maxSamplesPerPixel << "; got " << spp);
    return 1;
}

}  // namespace

Scene::Scene(SceneDesc desc) : desc_(std::move(desc)) {
    GpuMemory& memory = device_.memory();

    // Data buffers and the model buffers; an empty one (no light triangles) has no address and binds as a null
    // descriptor.
    bufferAddresses_.resize(desc_.buffers.size(), 0);
    for (size_t i = 0; i < desc_.buffers.size(); ++i) {
        const BufferDesc& b = desc_.buffers[i];
        if (b.isStatic() && !b.bytes.empty())
            bufferAddresses_[i] = memory.upload(b.bytes.data(), b.bytes.size(), b.name);
    }

    // One BLAS per bottom-level entry, geometries in file order (GeometryIndex, IDX-4). The device's build warnings
    // name a geometry and a primitive; each is kept with the scene file position of what it is about.
    std::set<std::pair<std::string, std::string>> seen;
    const auto takeWarnings = [&](const std::function<std::string(const dxr::Diagnostic&)>& whereOf) {
        for (dxr::Diagnostic d : device_.buildDiagnostics().warnings()) {
            if (!seen.insert({d.ruleId, d.message}).second) continue;
            d.message = whereOf(d) + d.message;
            buildWarnings_.push_back(std::move(d));
        }
    };
    for (const BlasDesc& blas : desc_.blases) {
        BottomLevelInputs inputs;
        inputs.Flags = blas.buildFlags;
        for (const GeometryDescFile& g : blas.geometries) {
            GeometryDesc d;
            d.Type = g.type;
            d.Flags = g.flags;
            if (g.type == GeometryType::Triangles) {
                d.Triangles.VertexBuffer = {bufferAddresses_[g.vertexBuffer] + g.vertexOffset, g.vertexStride};
                d.Triangles.VertexCount = g.vertexCount;
                d.Triangles.VertexFormat = g.vertexFormat;
                if (g.indexBuffer >= 0) {
                    d.Triangles.IndexBuffer = bufferAddresses_[size_t(g.indexBuffer)] + g.indexOffset;
                    d.Triangles.IndexCount = g.indexCount;
                    d.Triangles.IndexFormat = g.indexFormat;
                }
            } else {
                d.AABBs.AABBCount = g.aabbCount;
                d.AABBs.AABBs = {bufferAddresses_[g.aabbBuffer], sizeof(RaytracingAABB)};
            }
            inputs.GeometryDescs.push_back(d);
        }
        blasAddresses_.push_back(device_.buildBottomLevelAS(inputs));
        takeWarnings([&blas](const dxr::Diagnostic&) {
            return json::toString(blas.where) + ": bottom-level '" + blas.name + "': ";
        });
    }

    // The TLAS, instances in file order (InstanceIndex).
    std::vector<InstanceDesc> instances;
    for (const InstanceDescFile& i : desc_.instances)
        instances.push_back(
            makeInstanceDesc(i.transform, i.instanceID, i.mask, i.contribution, i.flags, blasAddresses_[i.blas]));
    tlas_ = device_.buildTopLevelAS({BUILD_FLAG_PREFER_FAST_TRACE, uint32_t(instances.size()), ElementsLayout::Array,
                                     memory.upload(instances, desc_.name + " instance descs")});
    takeWarnings([this](const dxr::Diagnostic& d) -> std::string {
        for (const dxr::DiagnosticValue& v : d.values)
            if (v.name == "InstanceIndex") {
                const size_t i = std::stoul(v.value);
                if (i < desc_.instances.size())
                    return json::toString(desc_.instances[i].where) + ": instance '" + desc_.instances[i].name + "': ";
            }
        return desc_.file.string() + ": ";
    });

    // Root signatures and the descriptor heap for the global tables.
    globalSignature_ = RootSignature::create(desc_.globalSignature);
    for (const RootSignatureDesc& l : desc_.localSignatures) localSignatures_.push_back(RootSignature::create(l));
    for (const GlobalArgumentDesc& a : desc_.globalArguments) heapSize_ += uint32_t(a.table.size());
    if (heapSize_ > 0) heap_ = &device_.createDescriptorHeap(heapSize_, desc_.name + " descriptor heap");

    // The models' textures (linear, as the files store them), one Texture2D per file however often it is bound.
    std::map<std::filesystem::path, Texture2DPtr> loaded;
    for (const GlobalArgumentDesc& a : desc_.globalArguments)
        for (const GlobalArgumentDesc::TableEntry& e : a.table) {
            if (!e.isTexture || e.texture.empty() || loaded.count(e.texture)) continue;
            loaded.emplace(e.texture, Texture2D::fromFile(e.texture.string()));
        }
    for (const GlobalArgumentDesc& a : desc_.globalArguments) {
        std::vector<Texture2DPtr>& textures = tableTextures_.emplace_back();
        for (const GlobalArgumentDesc::TableEntry& e : a.table)
            textures.push_back(e.isTexture && !e.texture.empty() ? loaded.at(e.texture) : Texture2DPtr{});
    }

    pipelineFor({});  // validates the state object and the tables now
}

Scene::Pipeline& Scene::pipelineFor(const LibraryOptions& options) {
    if (auto it = pipelines_.find(options); it != pipelines_.end()) return it->second;
    const ShaderLibraryBinding& binding = findShaderLibrary(desc_.shaderLibrary);

    StateObjectDesc so;
    so.name = desc_.name + " (" + std::string(procedural::toString(options.precision)) +
              (options.perturbation ? ", perturbed seed " + std::to_string(options.perturbation->seed) : "") + ")";
    std::vector<procedural::TraceRayArguments> traceRay;  // what the shaders pass, per ray type
    for (const RayTypeDesc& t : desc_.rayTypes)
        traceRay.push_back({t.rayContribution, t.multiplier, t.missShaderIndex, t.instanceInclusionMask});
    // The render's knobs with the scene's effects block: its reflectionDepth (unless a knob sets the depth) and the
    // call sites it switches off.
    const procedural::Accuracy accuracy = libraryAccuracy(desc_, options.accuracy);
    so.libraries = {
        {binding.make(options.precision, traceRay, accuracy, libraryEffects(desc_), options.perturbation), {}}};
    so.hitGroups = desc_.hitGroups;
    for (size_t i = 0; i < localSignatures_.size(); ++i)
        if (!desc_.localAssociations[i].empty())
            so.localRootSignatures.push_back({localSignatures_[i], desc_.localAssociations[i]});
    so.globalRootSignatures = {{globalSignature_, {}}};
    so.shaderConfigs = {{desc_.maxPayloadBytes, desc_.maxAttributeBytes}};
    // PORT: a recursion-depth knob is the shaders and the host recompiled with another MAX_RAY_RECURSION_DEPTH, so
    // the pipeline allows at least that depth.
    // The pipeline flag that skips a geometry type no ray reaches, where the ray flags allow it (scenes/effects.h).
    so.pipelineConfigs = {{pipelineRecursionDepth(desc_, accuracy), geometrySkipPipelineFlags(desc_)}};
    Pipeline p;
    p.stateObject = StateObject::create(so);

    GpuMemory& memory = device_.memory();
    const auto rayGen =
        ShaderTableBuilder("raygen").addRecord(p.stateObject->shaderIdentifier(desc_.rayGeneration)).upload(memory);
    p.tables.RayGenerationShaderRecord = {rayGen.StartAddress, rayGen.SizeInBytes};
    ShaderTableBuilder miss("miss");
    for (const std::string& m : desc_.missRecords)
        miss.addRecord(m.empty() ? ShaderIdentifier{} : p.stateObject->shaderIdentifier(m));
    p.tables.MissShaderTable = miss.upload(memory);
    ShaderTableBuilder hitGroups("hit groups");
    for (const RecordDesc& r : desc_.hitGroupRecords) {
        const ShaderIdentifier id = r.hitGroup.empty() ? ShaderIdentifier{} : p.stateObject->shaderIdentifier(r.hitGroup);
        if (r.localRootSignature < 0) {
            hitGroups.addRecord(id);
            continue;
        }
        LocalRootArguments args(localSignatures_[size_t(r.localRootSignature)]);
        for (const RecordDesc::Argument& a : r.arguments) {
            if (a.buffer >= 0) {
                // Generated buffers have no fixed address; local root descriptors must point at data.
                REFRAY_CHECK(desc_.buffers[size_t(a.buffer)].isStatic(),
                             json::toString(r.where) << ": " << r.origin << " binds generated buffer '"
                                                     << desc_.buffers[size_t(a.buffer)].name
                                                     << "' as a local root descriptor; records are written once, so "
                                                        "they can only point at data buffers");
                args.setDescriptor(a.parameter, bufferAddresses_[size_t(a.buffer)]);
            } else {
                args.setConstantBytes(a.parameter, a.dwords.data(), uint32_t(a.dwords.size() * 4));
            }
        }
        hitGroups.addRecord(id, args);
    }
    p.tables.HitGroupTable = hitGroups.upload(memory, desc_.hitGroupStride ? desc_.hitGroupStride : ~0ull);
    return pipelines_.emplace(options, std::move(p)).first->second;
}

GpuVirtualAddress Scene::generateBuffer(const BufferDesc& b, const CameraDesc& camera, float time, uint32_t width,
                                        uint32_t height, uint32_t seed, uint32_t samplesPerPixel) {
    GpuMemory& memory = device_.memory();
    switch (b.kind) {
        case BufferDesc::Kind::SceneConstants: {
            SceneConstantsInput in;
            in.projectionToWorld = projectionToWorld(camera, width, height);
            in.cameraPosition = vec4(vec3(camera.eye), 1.0f);
            in.light = desc_.light;
            in.elapsedTime = time;
            in.debugFlag = b.debugFlag;
            in.seed = seed;
            in.backgroundColor = b.backgroundColor;
            in.maxBounces = b.maxBounces;
            in.lightCount = desc_.lightTriangleCount();
            in.samplesPerPixel = samplesPerPixel;
            const std::vector<uint8_t> bytes = findShaderLibrary(desc_.shaderLibrary).sceneConstants(in);
            return memory.upload(bytes, b.name);
        }
        case BufferDesc::Kind::InstanceTransforms: {
            std::vector<Float4x4> matrices;
            for (uint32_t i : b.instances) {
                const InstanceDescFile& inst = desc_.instances[i];
                const std::optional<Matrix3x4> inverse = affineInverse(inst.transform);
                REFRAY_CHECK(inverse, json::toString(inst.where) << ": instance '" << inst.name
                                                                 << "' has a singular transform, so buffer '" << b.name
                                                                 << "' cannot hold its inverse");
                matrices.push_back(rowVectorForm(*inverse));      // world -> object
                matrices.push_back(rowVectorForm(inst.transform));  // object -> world
            }
            return memory.upload(matrices, b.name);
        }
        case BufferDesc::Kind::PrimitiveTransforms: {
            std::vector<Float4x4> matrices;
            for (const PrimitiveTransformDesc& p : b.primitives) {
                const auto [forward, inverse] = primitiveTransform(p, double(time));
                matrices.push_back(forward);
                matrices.push_back(inverse);
            }
            return memory.upload(matrices, b.name);
        }
        default: break;
    }
    REFRAY_ASSERT(false, "buffer '" << b.name << "' is not generated each frame");
    return 0;
}

RenderResult Scene::render(const RenderSettings& settings) {
    const ShaderLibraryBinding& binding = findShaderLibrary(desc_.shaderLibrary);
    const uint32_t k = sampleGridSize(settings.spp, binding);
    REFRAY_CHECK(k == 1 || !settings.region, "a launch region (one pixel's explanation) needs one sample per pixel, got --spp "
                                                 << settings.spp);
    const uint32_t shaderSamples = binding.samplesInShader ? settings.spp : 1;
    const uint32_t width = settings.width * k, height = settings.height * k;
    REFRAY_CHECK(settings.width > 0 && settings.height > 0 && width <= 65536 && height <= 65536,
                 "the dispatch " << width << "x" << height << " (size x sqrt(spp)) is outside 1x1 .. 65536x65536");
    const float time = settings.time.value_or(desc_.defaultTime);
    REFRAY_CHECK(std::isfinite(time) && time >= 0.0f, "--time must be a finite, non-negative number of seconds, got " << time);
    const CameraDesc& camera = desc_.camera(settings.camera);
    Pipeline& pipeline = pipelineFor({settings.precision, settings.accuracy, settings.perturbation});

    Image target(width, height);
    std::vector<GpuVirtualAddress> frameAddresses(desc_.buffers.size(), 0);
    for (size_t i = 0; i < desc_.buffers.size(); ++i)
        frameAddresses[i] = desc_.buffers[i].isStatic()
                                ? bufferAddresses_[i]
                                : generateBuffer(desc_.buffers[i], camera, time, width, height, settings.seed,
                                                 shaderSamples);

    GlobalRootArguments globals(globalSignature_);
    uint32_t slot = 0;
    for (size_t argument = 0; argument < desc_.globalArguments.size(); ++argument) {
        const GlobalArgumentDesc& a = desc_.globalArguments[argument];
        switch (a.kind) {
            case GlobalArgumentDesc::Kind::AccelerationStructure: globals.setDescriptor(a.parameter, tlas_); break;
            case GlobalArgumentDesc::Kind::Buffer: globals.setDescriptor(a.parameter, frameAddresses[size_t(a.buffer)]); break;
            case GlobalArgumentDesc::Kind::Table:
                globals.setDescriptor(a.parameter, heap_->gpuHandle(slot));
                for (size_t entry = 0; entry < a.table.size(); ++entry) {
                    const GlobalArgumentDesc::TableEntry& e = a.table[entry];
                    if (e.renderTarget) {
                        heap_->setTexture2D(slot++, DescriptorRangeType::UAV, &target);
                        continue;
                    }
                    if (e.isTexture) {
                        heap_->setTexture2D(slot++, tableTextures_[argument][entry]);
                        continue;
                    }
                    const BufferDesc& b = desc_.buffers[size_t(e.buffer)];
                    const GpuVirtualAddress address = frameAddresses[size_t(e.buffer)];
                    if (address == 0) {  // an empty model buffer: a null descriptor
                        heap_->setBuffer(slot++, e.type, BufferView{});
                        continue;
                    }
                    const uint64_t size = b.isStatic() ? b.bytes.size() : device_.memory().find(address)->size();
                    heap_->setBuffer(slot++, e.type, {address, size, e.stride});
                }
                break;
        }
    }

    RenderResult result;
    if (!desc_.computeShader.empty()) {  // one thread per pixel, in groups of the shader's numthreads
        const dxr::ShaderExport* cs = pipeline.stateObject->findComputeShader(desc_.computeShader);
        REFRAY_CHECK(cs, "the state object has no compute shader '" << desc_.computeShader << "'");
        const uvec3 n = cs->numThreads;
        const DispatchDesc dispatch{desc_.computeShader, (width + n.x - 1) / n.x, (height + n.y - 1) / n.y, 1};
        result.dispatch = dispatchComputeWithSettings(
            device_, dispatch, uvec3(dispatch.ThreadGroupCountX * n.x, dispatch.ThreadGroupCountY * n.y, n.z),
            pipeline.stateObject, &globals, settings);
    } else {
        DispatchRaysDesc desc = pipeline.tables;
        desc.Width = width;
        desc.Height = height;
        desc.Depth = 1;
        result.dispatch = dispatchWithSettings(device_, desc, pipeline.stateObject, &globals, settings);
    }
    reportNonFinitePixels(target, settings, result.dispatch.diagnostics);

    // k x k samples per output pixel, averaged in float in a fixed order (deterministic).
    if (k == 1) {
        result.image = std::move(target);
    } else {
        result.image = Image(settings.width, settings.height);
        const float weight = 1.0f / float(k * k);
        for (uint32_t y = 0; y < settings.height; ++y)
            for (uint32_t x = 0; x < settings.width; ++x) {
                vec4 sum(0.0f);
                for (uint32_t j = 0; j < k; ++j)
                    for (uint32_t i = 0; i < k; ++i) sum += target.at(x * k + i, y * k + j);
                result.image.at(x, y) = sum * weight;
            }
    }

    auto& meta = result.image.metadata;
    meta["scene"] = desc_.name;
    meta["scene_file"] = desc_.file.filename().string();
    meta["scene_sha256"] = desc_.fileHash;
    meta["shader_library"] = desc_.shaderLibrary;
    meta["camera"] = camera.name;
    if (!settings.time || *settings.time == desc_.defaultTime) {
        meta["time"] = desc_.defaultTimeText;  // as the scene file writes it
    } else {
        char text[32];
        const auto end = std::to_chars(text, text + sizeof text, time);  // shortest text that reads back as `time`
        meta["time"] = std::string(text, end.ptr);
    }
    meta["precision"] = std::string(procedural::toString(settings.precision));
    if (settings.perturbation) meta["perturbation"] = procedural::describe(*settings.perturbation);
    meta["spp"] = std::to_string(settings.spp);
    if (settings.seed) meta["seed"] = std::to_string(settings.seed);
    meta["knobs"] = describeKnobs(settings);
    if (desc_.effects.present) meta["effects"] = describeEffectsBlock(desc_.effects);
    meta["size"] = std::to_string(settings.width) + "x" + std::to_string(settings.height);
    meta["traversal_order"] = settings.order == TraversalOrder::Ordered
                                  ? "ordered"
                                  : "adversarial seed " + std::to_string(settings.adversarialSeed);
    return result;
}

std::unique_ptr<Scene> loadScene(const std::filesystem::path& path) {
    return std::make_unique<Scene>(loadSceneFile(path));
}

}  // namespace refray::scenes
