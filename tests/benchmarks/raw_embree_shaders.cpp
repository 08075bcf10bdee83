// The raw-Embree renderer: the ports' intersection shaders without the shader API, ray generation, TraceRay,
// closest hits and misses.
#include "tests/benchmarks/raw_embree_renderer.h"

namespace refray::bench {

// ---- Intersection: the ports' intersection shaders without the shader API ----------------------------

bool RawRenderer::intersect(const RawGeometry& g, const vec3& origin, const vec3& direction, float tMin,
                            float tCurrent, float& tHit, ProceduralAttributes& attributes) const {
    const vec3 objectRayOrigin = g.worldToObject.transformPoint(origin);
    const vec3 objectRayDirection = g.worldToObject.transformVector(direction);
    if (!boxOverlaps(g.boxMin, g.boxMax, objectRayOrigin, objectRayDirection, tMin, tCurrent)) return false;
    const math::RayExtent<float> extent{tMin, tCurrent, kCullBackFacing, false};

    // D3D12: the object ray through bottomLevelASToLocalSpace, not renormalised; NormalToWorld through
    // localSpaceToBottomLevelAS and ObjectToWorld3x4.
    const auto d3d12LocalRay = [&] {
        return math::Ray<float>{vec3(procedural::mul(vec4(objectRayOrigin, 1.0f), g.bottomLevelASToLocalSpace)),
                                procedural::mul3x3(objectRayDirection, g.bottomLevelASToLocalSpace)};
    };
    const auto d3d12NormalToWorld = [&](const vec3& localNormal) {
        const vec3 n = procedural::mul3x3(localNormal, g.localSpaceToBottomLevelAS);
        const Matrix3x4& o2w = g.objectToWorld;
        vec3 r;
        for (size_t i = 0; i < 3; ++i)
            r[glm::length_t(i)] = o2w.m[i][0] * n.x + o2w.m[i][1] * n.y + o2w.m[i][2] * n.z;
        return hlsl::normalize(r);
    };
    // Proceduray: the world ray through g_instanceBuffer's world -> object matrix, direction normalised (H1);
    // normalize(mul(n, (float3x3)WorldToObject3x4())).
    const auto procedurayLocalRay = [&] {
        return math::Ray<float>{vec3(procedural::mul(vec4(origin, 1.0f), g.localSpaceToBottomLevelAS)),
                                hlsl::normalize(procedural::mul3x3(direction, g.localSpaceToBottomLevelAS))};
    };
    const auto procedurayNormalToWorld = [&](const vec3& n) {
        const Matrix3x4& w = g.worldToObject;
        vec3 r;
        for (int j = 0; j < 3; ++j)
            r[j] = n.x * w.m[0][size_t(j)] + n.y * w.m[1][size_t(j)] + n.z * w.m[2][size_t(j)];
        return hlsl::normalize(r);
    };

    bool hit = false;
    float t = 0.0f;
    attributes = ProceduralAttributes{};
    switch (g.intersection) {
        case Intersection::D3D12Analytic: {
            const math::Ray<float> localRay = d3d12LocalRay();
            math::AnalyticHit<float> test;
            switch (d3d12::AnalyticPrimitive::Enum(g.aabbCB.primitiveType)) {
                case d3d12::AnalyticPrimitive::AABB: test = math::RayUnitCubeIntersectionTest(localRay, extent); break;
                case d3d12::AnalyticPrimitive::Spheres:
                    test = math::RaySpheresIntersectionTest(localRay, extent);
                    break;
                default: break;
            }
            if (test.hit) {
                hit = true;
                t = test.thit;
                attributes.normal = d3d12NormalToWorld(test.normal);
            }
            break;
        }
        case Intersection::D3D12Volumetric: {
            math::MetaballsHit<float> test;
            if (d3d12::VolumetricPrimitive::Enum(g.aabbCB.primitiveType) == d3d12::VolumetricPrimitive::Metaballs)
                test = math::RayMetaballsIntersectionTest(d3d12LocalRay(), extent, elapsedTime_, 12.0f,
                                                          d3d12::metaballsParams<float>(accuracy_));
            if (test.hit) {
                hit = true;
                t = test.thit;
                attributes.normal = d3d12NormalToWorld(test.normal);
            }
            break;
        }
        case Intersection::D3D12SignedDistance: {
            const auto primitiveType = d3d12::SignedDistancePrimitive(g.aabbCB.primitiveType);
            const math::SphereTraceParams<float> params =
                d3d12::sphereTraceParams(accuracy_, float(g.material.stepScale));
            const auto sdf = [primitiveType](const vec3& position) {
                return math::d3d12::GetDistanceFromSignedDistancePrimitive(position, primitiveType);
            };
            const math::SphereTraceResult<float> test =
                math::RaySignedDistancePrimitiveTest(d3d12LocalRay(), extent, sdf, params);
            if (test.hit) {
                hit = true;
                t = test.thit;
                attributes.normal = d3d12NormalToWorld(test.normal);
            }
            break;
        }
        case Intersection::Pacman: {
            const float mouth = math::pacman::PacmanMouthInterpolant(elapsedTime_);
            const math::SphereTraceParams<float> params =
                pray::sphereTraceParams(accuracy_, float(g.material.stepScale));
            // The port's GetDistanceFromSignedDistancePrimitive for IntersectedRoundCube, the only live case.
            const auto sdf = [mouth](const vec3& p) { return math::pacman::pacMan(p, mouth); };
            const math::SphereTraceResult<float> test =
                math::RaySignedDistancePrimitiveTest(procedurayLocalRay(), extent, sdf, params);
            if (test.hit && test.thit < tCurrent) {
                hit = true;
                t = test.thit;
                attributes.color = math::pacman::PacmanHitColor(test.normal, test.position);
                attributes.normal = procedurayNormalToWorld(test.normal);
            }
            break;
        }
        case Intersection::Mandelbulb: {
            const math::Ray<float> localRay = procedurayLocalRay();
            const int iMax = pray::mandelbulbStepCount(
                math::mandelbulb::MandelbulbIterationCount(elapsedTime_, int(g.aabbCB.instanceIndex)), accuracy_);
            const math::mandelbulb::MandelbulbHit<float> test = math::mandelbulb::MandelbulbDistance(
                localRay.origin, localRay.direction, iMax, pray::mandelbulbParams<float>(accuracy_));
            if (test.hit && test.thit < tCurrent) {
                hit = true;
                t = test.thit;
                attributes.color = test.color;
                attributes.normal = procedurayNormalToWorld(test.normal);
            }
            break;
        }
        case Intersection::Julia: {
            const math::Ray<float> localRay = procedurayLocalRay();
            const math::julia::JuliaHit<float> test =
                math::julia::JuliaDistance(localRay.origin, localRay.direction, pray::juliaParams<float>(accuracy_));
            const vec2 thit = test.resT;
            if (test.hit && thit.x < tCurrent) {
                hit = true;
                t = thit.x;
                attributes.normal = procedurayNormalToWorld(test.normal);
                attributes.color = vec4(thit, 0.0f, 0.0f);  // (t, iteration count) for the closest hit
            }
            break;
        }
        case Intersection::None: break;
    }
    // ReportHit accepts TMin <= t <= RayTCurrent.
    if (!hit || !(t >= tMin && t <= tCurrent)) return false;
    tHit = t;
    return true;
}

// ---- Ray generation, TraceRay, closest hits and misses ------------------------------------------------

uint64_t RawRenderer::render(uint32_t threads, std::vector<vec4>& image) const {
    image.assign(size_t(width_) * height_, vec4(0.0f));
    std::atomic<uint64_t> rays{0};
    tbb::task_arena arena{int(threads)};
    arena.execute([&] {
        tbb::parallel_for(tbb::blocked_range2d<uint32_t>(0, height_, 8, 0, width_, 8), [&](const auto& r) {
            [[maybe_unused]] procedural::PrecisionScope<float> scope;  // float shader math flushes denormals
            PixelState px;
            px.dimensions = uvec2(width_, height_);
            for (uint32_t y = r.rows().begin(); y < r.rows().end(); ++y)
                for (uint32_t x = r.cols().begin(); x < r.cols().end(); ++x) {
                    px.index = uvec2(x, y);
                    vec3 origin, direction;
                    procedural::GenerateCameraRay(px.index, px.dimensions, cameraPosition_, projectionToWorld_, origin,
                                                  direction);
                    image[size_t(y) * width_ + x] = traceRadianceRay(origin, direction, 0, px);
                }
            rays += px.rays;
        });
    });
    throwIfFailed("rendering with raw Embree");
    return rays.load();
}

vec4 RawRenderer::traceRadianceRay(const vec3& origin, const vec3& direction, uint32_t currentRayRecursionDepth,
                                   PixelState& px) const {
    if (currentRayRecursionDepth >= maxDepth_) return vec4(0.0f);
    ++px.rays;
    RayContext context;
    rtcInitIntersectContext(&context.embree);
    RTCRayHit rayhit;
    rayhit.ray = RTCRay{origin.x, origin.y, origin.z, 0.0f, direction.x, direction.y, direction.z, 0.0f, kTMax,
                        0xFFFFFFFFu, 0, 0};
    rayhit.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rayhit.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene_, &context.embree, &rayhit);
    if (rayhit.hit.geomID == RTC_INVALID_GEOMETRY_ID)  // MyMissShader / Miss
        return library_ == Library::D3D12 ? d3d12::BackgroundColor : pray::kBackgroundColor;

    const RawGeometry& g = *geometries_[rayhit.hit.geomID];
    const RawHit hit{origin, direction, rayhit.ray.tfar, rayhit.hit.primID, context.attributes};
    const uint32_t recursionDepth = currentRayRecursionDepth + 1;  // the payload's recursionDepth
    switch (g.closestHit) {
        case ClosestHit::D3D12Triangle: return closestHitD3D12Triangle(g, hit, recursionDepth, px);
        case ClosestHit::D3D12AABB: return closestHitD3D12AABB(g, hit, recursionDepth, px);
        case ClosestHit::ProcedurayTriangle: return closestHitProcedurayTriangle(g, hit, recursionDepth, px);
        case ClosestHit::Pacman: return closestHitPacman(g, hit, recursionDepth, px);
        case ClosestHit::Mandelbulb: return closestHitMandelbulb(g, hit, recursionDepth, px);
        case ClosestHit::Julia: return closestHitJulia(g, hit, recursionDepth, px);
    }
    return vec4(0.0f);
}

// TMax 10000 as in both libraries; a hit anywhere is a shadow (no closest hit; the miss clears it).
bool RawRenderer::traceShadowRayAndReportIfHit(const vec3& origin, const vec3& direction,
                                               uint32_t currentRayRecursionDepth, PixelState& px) const {
    if (currentRayRecursionDepth >= maxDepth_) return false;
    if (!effects_.traceShadowRays) return false;
    ++px.rays;
    RayContext context;
    rtcInitIntersectContext(&context.embree);
    RTCRay ray{origin.x, origin.y, origin.z, 0.0f, direction.x, direction.y, direction.z, 0.0f, kTMax,
               0xFFFFFFFFu, 0, 0};
    rtcOccluded1(scene_, &context.embree, &ray);
    return ray.tfar < 0.0f;
}

bool RawRenderer::traceShadowRayTowardsLight(const vec3& hitPosition, uint32_t recursionDepth, PixelState& px) const {
    return traceShadowRayAndReportIfHit(hitPosition, hlsl::normalize(lightPosition_ - hitPosition), recursionDepth, px);
}

// reflectanceCoef·(Fresnel, 1)·(reflection ray colour), the reflection ray leaving HitWorldPosition().
vec4 RawRenderer::reflectedColor(const RawHit& hit, const vec3& normal, float reflectanceCoef, const vec3& f0,
                                 uint32_t recursionDepth, PixelState& px) const {
    const vec3 D = hit.direction;
    const vec4 reflectionColor = traceRadianceRay(hit.position(), hlsl::reflect(D, normal), recursionDepth, px);
    const vec3 fresnelR = procedural::FresnelReflectanceSchlick(D, normal, f0);
    return reflectanceCoef * vec4(fresnelR, 1.0f) * reflectionColor;
}

// The normal of the triangle's first vertex, read as the closest hits read it: g_indices at PrimitiveIndex() x 6
// bytes (Load2 of the aligned dwords), then g_vertices[index].normal; reads past the end give 0.
vec3 RawRenderer::storedVertexNormal(uint32_t primitiveIndex) const {
    const uint32_t baseIndex = primitiveIndex * 3 * 2;
    const uvec3 indices = procedural::Load3x16BitIndices(baseIndex, indexBytes_.data(), indexBytes_.size());
    const size_t offset = size_t(indices[0]) * sizeof(procedural::Vertex) + offsetof(procedural::Vertex, normal);
    vec3 normal(0.0f);
    if (offset + sizeof normal <= vertexBytes_.size())
        std::memcpy(&normal, vertexBytes_.data() + offset, sizeof normal);
    return normal;
}

vec4 RawRenderer::closestHitD3D12Triangle(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                          PixelState& px) const {
    const PrimitiveConstantBuffer& l_materialCB = g.material;
    const vec3 triangleNormal = storedVertexNormal(hit.primitiveIndex);
    const bool shadowRayHit = traceShadowRayTowardsLight(hit.position(), recursionDepth, px);
    const float checkers = d3d12::AnalyticalCheckersTexture(hit.position(), triangleNormal, cameraPosition_,
                                                            projectionToWorld_, px.index, px.dimensions);
    vec4 reflected(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflected = reflectedColor(hit, triangleNormal, l_materialCB.reflectanceCoef, vec3(l_materialCB.albedo),
                                   recursionDepth, px);
    const vec4 phongColor = d3d12::CalculatePhongLighting(
        d3d12CB_, l_materialCB.albedo, triangleNormal, shadowRayHit, l_materialCB.diffuseCoef,
        l_materialCB.specularCoef, l_materialCB.specularPower, hit.position(), hit.direction);
    const vec4 color = checkers * (phongColor + reflected);
    return d3d12::ApplyVisibilityFalloff(color, hit.t);
}

vec4 RawRenderer::closestHitD3D12AABB(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                      PixelState& px) const {
    const PrimitiveConstantBuffer& l_materialCB = g.material;
    const vec3 normal = hit.attributes.normal;
    const bool shadowRayHit = traceShadowRayTowardsLight(hit.position(), recursionDepth, px);
    vec4 reflected(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflected =
            reflectedColor(hit, normal, l_materialCB.reflectanceCoef, vec3(l_materialCB.albedo), recursionDepth, px);
    const vec4 phongColor = d3d12::CalculatePhongLighting(
        d3d12CB_, l_materialCB.albedo, normal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef,
        l_materialCB.specularPower, hit.position(), hit.direction);
    const vec4 color = phongColor + reflected;
    return d3d12::ApplyVisibilityFalloff(color, hit.t);
}

// The Proceduray closest hits add the payload's colour, still the vec4(0) TraceRadianceRay starts it with.
vec4 RawRenderer::closestHitProcedurayTriangle(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                               PixelState& px) const {
    const PrimitiveConstantBuffer& l_materialCB = g.material;
    const vec3 triangleNormal = -storedVertexNormal(hit.primitiveIndex);
    const bool shadowRayHit = traceShadowRayTowardsLight(hit.position(), recursionDepth, px);
    const vec4 albedo = l_materialCB.albedo;
    vec4 reflected(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflected = reflectedColor(hit, triangleNormal, l_materialCB.reflectanceCoef, vec3(albedo), recursionDepth, px);
    const vec4 phongColor = pray::CalculatePhongLighting(
        procedurayCB_, albedo, triangleNormal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef,
        l_materialCB.specularPower, hit.position(), hit.direction);
    vec4 color = phongColor + reflected;
    color += vec4(0.0f);
    return color;
}

vec4 RawRenderer::closestHitPacman(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                   PixelState& px) const {
    const PrimitiveConstantBuffer& l_materialCB = g.material;
    const vec3 normal = hit.attributes.normal;
    const vec4 albedo = l_materialCB.albedo;
    const bool shadowRayHit = traceShadowRayTowardsLight(hit.position(), recursionDepth, px);
    vec4 reflected(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflected = reflectedColor(hit, normal, l_materialCB.reflectanceCoef, vec3(albedo), recursionDepth, px);
    const vec4 phongColor = pray::CalculatePhongLighting(
        procedurayCB_, albedo, normal, shadowRayHit, l_materialCB.diffuseCoef, l_materialCB.specularCoef,
        l_materialCB.specularPower, hit.position(), hit.direction);
    vec4 color = hit.attributes.color * (phongColor + reflected);
    color += vec4(0.0f);
    return color;
}

vec4 RawRenderer::closestHitMandelbulb(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                       PixelState& px) const {
    const PrimitiveConstantBuffer& l_materialCB = g.material;
    const vec3 normal = hit.attributes.normal;
    vec4 color = pray::MandelbulbSurfaceColor(hit.direction, normal, hit.attributes.color);
    vec4 reflected(0.0f);
    if (l_materialCB.reflectanceCoef > 0.001f)
        reflected =
            reflectedColor(hit, normal, l_materialCB.reflectanceCoef, vec3(l_materialCB.albedo), recursionDepth, px);
    color = color + reflected;
    color += vec4(0.0f);
    return color;
}

vec4 RawRenderer::closestHitJulia(const RawGeometry& g, const RawHit& hit, uint32_t recursionDepth,
                                  PixelState& px) const {
    const vec3 normal = hit.attributes.normal;
    const bool shadowRayHit = false;  // commented out in the HLSL
    // H1: with the local-unit t this point lies near the object-space ray origin.
    const vec3 objectRayOrigin = g.worldToObject.transformPoint(hit.origin);
    const vec3 objectRayDirection = g.worldToObject.transformVector(hit.direction);
    const vec3 pos = objectRayOrigin + hit.t * objectRayDirection;
    vec4 albedo = vec4(3.5f * pray::colorSurface(pos, vec2(hit.attributes.color)), 1.0f);
    if (recursionDepth == maxDepth_ - 1) albedo += 1.65f * hlsl::step(0.0f, hlsl::abs(pos.y));
    const float reflecCoef = 0.1f;
    vec4 reflected(0.0f);
    if (reflecCoef > 0.001f) reflected = reflectedColor(hit, normal, reflecCoef, vec3(albedo), recursionDepth, px);
    const float diffuseCoef = 0.6f, specularCoef = 0.08f, specularPower = 0.2f;
    const vec4 phongColor = pray::CalculatePhongLighting(procedurayCB_, albedo, normal, shadowRayHit, diffuseCoef,
                                                         specularCoef, specularPower, hit.position(), hit.direction);
    vec4 color = phongColor + reflected;
    color += vec4(0.0f);
    return color;
}

}  // namespace refray::bench
