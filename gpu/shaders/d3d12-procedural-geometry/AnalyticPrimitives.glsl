// Ports AnalyticPrimitives.hlsli of microsoft/DirectX-Graphics-Samples@357ade6e,
// Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/AnalyticPrimitives.hlsli.
// Set of ray vs analytic primitive intersection tests. Intersection shaders only (reads RayTMin/RayTCurrent/RayFlags).
#ifndef ANALYTICPRIMITIVES_GLSL
#define ANALYTICPRIMITIVES_GLSL

// Solve a quadratic equation.
// Ref: https://www.scratchapixel.com/lessons/3d-basic-rendering/minimal-ray-tracer-rendering-simple-shapes/ray-sphere-intersection
bool SolveQuadraticEqn(float a, float b, float c, inout float x0, inout float x1)
{
    float discr = b * b - 4 * a * c;
    if (discr < 0) return false;
    else if (discr == 0) x0 = x1 = -0.5 * b / a;
    else {
        float q = (b > 0) ?
            -0.5 * (b + sqrt(discr)) :
            -0.5 * (b - sqrt(discr));
        x0 = q / a;
        x1 = c / q;
    }
    if (x0 > x1) swap(x0, x1);

    return true;
}

// Calculate a normal for a hit point on a sphere.
vec3 CalculateNormalForARaySphereHit(in Ray ray, in float thit, vec3 center)
{
    vec3 hitPosition = ray.origin + thit * ray.direction;
    return normalize(hitPosition - center);
}

// Analytic solution of an unbounded ray sphere intersection points.
// Ref: https://www.scratchapixel.com/lessons/3d-basic-rendering/minimal-ray-tracer-rendering-simple-shapes/ray-sphere-intersection
bool SolveRaySphereIntersectionEquation(in Ray ray, inout float tmin, inout float tmax, in vec3 center, in float radius)
{
    vec3 L = ray.origin - center;
    float a = dot(ray.direction, ray.direction);
    float b = 2 * dot(ray.direction, L);
    float c = dot(L, L) - radius * radius;
    return SolveQuadraticEqn(a, b, c, tmin, tmax);
}

// Test if a ray with RayFlags and segment <RayTMin(), RayTCurrent()> intersects a hollow sphere.
// PORT: GLSL has no default arguments; every HLSL caller passes center and radius.
bool RaySphereIntersectionTest(in Ray ray, inout float thit, inout float tmax, out ProceduralPrimitiveAttributes attr, in vec3 center, in float radius)
{
    float t0, t1; // solutions for t if the ray intersects

    if (!SolveRaySphereIntersectionEquation(ray, t0, t1, center, radius)) return false;
    tmax = t1;

    if (t0 < RayTMin())
    {
        // t0 is before RayTMin, let's use t1 instead .
        if (t1 < RayTMin()) return false; // both t0 and t1 are before RayTMin

        attr.normal = CalculateNormalForARaySphereHit(ray, t1, center);
        if (IsAValidHit(ray, t1, attr.normal))
        {
            thit = t1;
            return true;
        }
    }
    else
    {
        attr.normal = CalculateNormalForARaySphereHit(ray, t0, center);
        if (IsAValidHit(ray, t0, attr.normal))
        {
            thit = t0;
            return true;
        }

        attr.normal = CalculateNormalForARaySphereHit(ray, t1, center);
        if (IsAValidHit(ray, t1, attr.normal))
        {
            thit = t1;
            return true;
        }
    }
    return false;
}

// Test if a ray segment <RayTMin(), RayTCurrent()> intersects a solid sphere.
// Limitation: this test does not take RayFlags into consideration and does not calculate a surface normal.
bool RaySolidSphereIntersectionTest(in Ray ray, inout float thit, inout float tmax, in vec3 center, in float radius)
{
    float t0, t1; // solutions for t if the ray intersects

    if (!SolveRaySphereIntersectionEquation(ray, t0, t1, center, radius))
        return false;

    // Since it's a solid sphere, clip intersection points to ray extents.
    thit = hlsl_max(t0, RayTMin());
    tmax = hlsl_min(t1, RayTCurrent());

    return true;
}

// Test if a ray with RayFlags and segment <RayTMin(), RayTCurrent()> intersects multiple hollow spheres.
bool RaySpheresIntersectionTest(in Ray ray, out float thit, out ProceduralPrimitiveAttributes attr)
{
    const int N = 3;
    vec3 centers[N] =
    {
        vec3(-0.3, -0.3, -0.3),
        vec3(0.1, 0.1, 0.4),
        vec3(0.35,0.35, 0.0)
    };
    float  radii[N] = { 0.6, 0.3, 0.15 };
    bool hitFound = false;

    //
    // Test for intersection against all spheres and take the closest hit.
    //
    thit = RayTCurrent();

    // test against all spheres
    for (int i = 0; i < N; i++)
    {
        float _thit;
        float _tmax;
        ProceduralPrimitiveAttributes _attr = ProceduralPrimitiveAttributes(vec3(0));
        if (RaySphereIntersectionTest(ray, _thit, _tmax, _attr, centers[i], radii[i]))
        {
            if (_thit < thit)
            {
                thit = _thit;
                attr = _attr;
                hitFound = true;
            }
        }
    }
    return hitFound;
}

// Test if a ray segment <RayTMin(), RayTCurrent()> intersects an AABB.
// Limitation: this test does not take RayFlags into consideration and does not calculate a surface normal.
// Ref: https://www.scratchapixel.com/lessons/3d-basic-rendering/minimal-ray-tracer-rendering-simple-shapes/ray-box-intersection
bool RayAABBIntersectionTest(Ray ray, vec3 aabb[2], out float tmin, out float tmax)
{
    vec3 tmin3, tmax3;
    ivec3 sign3 = ivec3(greaterThan(ray.direction, vec3(0)));

    // Handle rays parallel to any x|y|z slabs of the AABB.
    // If a ray is within the parallel slabs,
    //  the tmin, tmax will get set to -inf and +inf
    //  which will get ignored on tmin/tmax = max/min.
    // If a ray is outside the parallel slabs, -inf/+inf will
    //  make tmax > tmin fail (i.e. no intersection).
    // TODO: handle cases where ray origin is within a slab
    //  that a ray direction is parallel to. In that case
    //  0 * INF => NaN
    const float FLT_INFINITY = INFINITY;
    // HLSL 2021 select(c, a, b) is per component; so is GLSL mix(b, a, bvec c) (selection, no arithmetic).
    vec3 invRayDirection = mix(mix(vec3(-FLT_INFINITY), vec3(FLT_INFINITY), greaterThan(ray.direction, vec3(0))),
                               1 / ray.direction,
                               notEqual(ray.direction, vec3(0)));

    tmin3.x = (aabb[1 - sign3.x].x - ray.origin.x) * invRayDirection.x;
    tmax3.x = (aabb[sign3.x].x - ray.origin.x) * invRayDirection.x;

    tmin3.y = (aabb[1 - sign3.y].y - ray.origin.y) * invRayDirection.y;
    tmax3.y = (aabb[sign3.y].y - ray.origin.y) * invRayDirection.y;

    tmin3.z = (aabb[1 - sign3.z].z - ray.origin.z) * invRayDirection.z;
    tmax3.z = (aabb[sign3.z].z - ray.origin.z) * invRayDirection.z;

    tmin = hlsl_max(hlsl_max(tmin3.x, tmin3.y), tmin3.z);
    tmax = hlsl_min(hlsl_min(tmax3.x, tmax3.y), tmax3.z);

    return tmax > tmin && tmax >= RayTMin() && tmin <= RayTCurrent();
}

// Test if a ray with RayFlags and segment <RayTMin(), RayTCurrent()> intersects a hollow AABB.
bool RayAABBIntersectionTest(Ray ray, vec3 aabb[2], inout float thit, inout ProceduralPrimitiveAttributes attr)
{
    float tmin, tmax;
    if (RayAABBIntersectionTest(ray, aabb, tmin, tmax))
    {
        // Only consider intersections crossing the surface from the outside.
        if (tmin < RayTMin() || tmin > RayTCurrent())
            return false;

        thit = tmin;

        // Set a normal to the normal of a face the hit point lays on.
        vec3 hitPosition = ray.origin + thit * ray.direction;
        vec3 distanceToBounds[2] = {
            abs(aabb[0] - hitPosition),
            abs(aabb[1] - hitPosition)
        };
        const float eps = 0.0001;
        if (distanceToBounds[0].x < eps) attr.normal = vec3(-1, 0, 0);
        else if (distanceToBounds[0].y < eps) attr.normal = vec3(0, -1, 0);
        else if (distanceToBounds[0].z < eps) attr.normal = vec3(0, 0, -1);
        else if (distanceToBounds[1].x < eps) attr.normal = vec3(1, 0, 0);
        else if (distanceToBounds[1].y < eps) attr.normal = vec3(0, 1, 0);
        else if (distanceToBounds[1].z < eps) attr.normal = vec3(0, 0, 1);

        return IsAValidHit(ray, thit, attr.normal);
    }
    return false;
}

#endif // ANALYTICPRIMITIVES_GLSL
