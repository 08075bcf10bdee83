// Ports SignedDistancePrimitives.hlsli of microsoft/DirectX-Graphics-Samples@357ade6e,
// Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/SignedDistancePrimitives.hlsli.
// (Its distance functions: MIT License, Copyright(c) 2013 Inigo Quilez; see the HLSL file.)
// A list of useful distance function to simple primitives, and an example on how to
// do some interesting boolean operations, repetition and displacement.
// More info here: http://www.iquilezles.org/www/articles/distfunctions/distfunctions.htm
//
// The functions the sample never calls (reference-scene-d3d12-procedural.md I10) are ported too, so the file reads
// side by side with the HLSL. RaySignedDistancePrimitiveTest is for intersection shaders only (DXR_STAGE_ guard),
// and for shaders that trace inline with the query's extent (DXR_RAY_EXTENT_OF_QUERY, InlineShadows.glsl).
#ifndef SIGNEDDISTANCEPRIMITIVES_GLSL
#define SIGNEDDISTANCEPRIMITIVES_GLSL

//------------------------------------------------------------------
// PORT: HLSL's enum parameter SignedDistancePrimitive::Enum is a uint here.
float GetDistanceFromSignedDistancePrimitive(in vec3 position, in uint sdPrimitive);

//------------------------------------------------------------------

// Subtract: Obj1 - Obj2
float opS(float d1, float d2)
{
    return hlsl_max(d1, -d2);
}

// Union: Obj1 + Obj2
float opU(float d1, float d2)
{
    return hlsl_min(d1, d2);
}

// Intersection: Obj1 & Obj2
float opI(float d1, float d2)
{
    return hlsl_max(d1, d2);
}

// Repetitions
vec3 opRep(vec3 p, vec3 c)
{
    return fmod(p, c) - 0.5 * c;
}

// Polynomial smooth min/union (k = 0.1)
// Ref: http://www.iquilezles.org/www/articles/smin/smin.htm
// PORT: HLSL clamp lowers to FMax then FMin (NaN-ignoring), hence hlsl_nclamp.
float smin(float a, float b, float k)
{
    float h = hlsl_nclamp(0.5 + 0.5*(b - a) / k, 0.0, 1.0);
    return lerp(b, a, h) - k * h*(1.0 - h);
}


// Polynomial smooth min/union (k = 0.1)
float smax(float a, float b, float k)
{
    float h = hlsl_nclamp(0.5 + 0.5*(b - a) / k, 0.0, 1.0);
    return lerp(a, b, h) + k * h*(1.0 - h);
}

// Smooth blend as union
float opBlendU(float d1, float d2)
{
    return smin(d1, d2, 0.1);
}

// Smooth blend as intersect
float opBlendI(float d1, float d2)
{
    return smax(d1, d2, 0.1);
}


// Twist
vec3 opTwist(vec3 p)
{
    float c = cos(3.0 * p.y);
    float s = sin(3.0 * p.y);
    // PORT: HLSL float2x2(c, -s, s, c) fills rows: rows (c, -s) and (s, c), and mul(m, v) is the column product
    // (c*x - s*z, s*x + c*z). GLSL mat2(c, -s, s, c) fills columns with the same numbers, so v * m is that product.
    mat2 m = mat2(c, -s, s, c);
    return vec3(p.xz * m, p.y);
}


//------------------------------------------------------------------

float sdPlane(vec3 p)
{
    return p.y;
}

float sdSphere(vec3 p, float s)
{
    return length(p) - s;
}

// Box extents: <-b,b>
float sdBox(vec3 p, vec3 b)
{
    vec3 d = abs(p) - b;
    return hlsl_min(hlsl_max(d.x, hlsl_max(d.y, d.z)), 0.0) + length(hlsl_max(d, vec3(0.0)));
}

float sdEllipsoid(in vec3 p, in vec3 r)
{
    return (length(p / r) - 1.0) * hlsl_min(hlsl_min(r.x, r.y), r.z);
}

float udRoundBox(vec3 p, vec3 b, float r)
{
    return length(hlsl_max(abs(p) - b, vec3(0.0))) - r;
}

// t: {radius, tube radius}
float sdTorus(vec3 p, vec2 t)
{
    vec2 q = vec2(length(p.xz) - t.x, p.y);
    return length(q) - t.y;
}

float sdHexPrism(vec3 p, vec2 h)
{
    vec3 q = abs(p);
    float d1 = q.z - h.y;
    float d2 = hlsl_max((q.x * 0.866025 + q.y * 0.5), q.y) - h.x;
    return length(hlsl_max(vec2(d1, d2), vec2(0.0))) + hlsl_min(hlsl_max(d1, d2), 0.);
}

float sdCapsule(vec3 p, vec3 a, vec3 b, float r)
{
    vec3 pa = p - a, ba = b - a;
    float h = hlsl_nclamp(dot(pa, ba) / dot(ba, ba), 0.0, 1.0);
    return length(pa - ba * h) - r;
}

float sdEquilateralTriangle(in vec2 p)
{
    const float k = 1.73205;    //sqrt(3.0);
    p.x = abs(p.x) - 1.0;
    p.y = p.y + 1.0 / k;
    if (p.x + k * p.y > 0.0) p = vec2(p.x - k * p.y, -k * p.x - p.y) / 2.0;
    p.x += 2.0 - 2.0 * hlsl_nclamp((p.x + 2.0) / 2.0, 0.0, 1.0);
    return -length(p) * sign(p.y);
}

float sdTriPrism(vec3 p, vec2 h)
{
    vec3 q = abs(p);
    float d1 = q.z - h.y;
#if 1
    // distance bound
    float d2 = hlsl_max(q.x * 0.866025 + p.y * 0.5, -p.y) - h.x * 0.5;
#else
    // correct distance
    h.x *= 0.866025;
    float d2 = sdEquilateralTriangle(p.xy / h.x) * h.x;
#endif
    return length(hlsl_max(vec2(d1, d2), vec2(0.0))) + hlsl_min(hlsl_max(d1, d2), 0.);
}

float sdCylinder(vec3 p, vec2 h)
{
    vec2 d = abs(vec2(length(p.xz), p.y)) - h;
    return hlsl_min(hlsl_max(d.x, d.y), 0.0) + length(hlsl_max(d, vec2(0.0)));
}

float sdCone(in vec3 p, in vec3 c)
{
    vec2 q = vec2(length(p.xz), p.y);
    float d1 = -q.y - c.z;
    float d2 = hlsl_max(dot(q, c.xy), q.y);
    return length(hlsl_max(vec2(d1, d2), vec2(0.0))) + hlsl_min(hlsl_max(d1, d2), 0.);
}

float sdConeSection(in vec3 p, in float h, in float r1, in float r2)
{
    float d1 = -p.y - h;
    float q = p.y - h;
    float si = 0.5 * (r1 - r2) / h;
    float d2 = hlsl_max(sqrt(dot(p.xz, p.xz) * (1.0 - si * si)) + q * si - r2, q);
    return length(hlsl_max(vec2(d1, d2), vec2(0.0))) + hlsl_min(hlsl_max(d1, d2), 0.);
}


// h = { sin a, cos a, height of a pyramid }
// a = pyramid's inner angle between its side plane and a ground plane.
// Octahedron position - ground plane intersecting in the middle.
float sdOctahedron(vec3 p, vec3 h)
{
    float d = 0.0;

    // Get distance against pyramid's sides going through origin.
    // Test: d = p.x * sin a + p.y * cos a
    d = dot(vec2(hlsl_max(abs(p.x), abs(p.z)), abs(p.y)),
            vec2(h.x, h.y));

    // Subtract distance to a side when at height h.z from the origin.
    return d - h.y * h.z;
}

// h = { sin a, cos a, height of a pyramid}
// a = pyramid's inner angle between its side plane and a ground plane.
// Pyramid position - sitting on a ground plane.
float sdPyramid(vec3 p, vec3 h) // h = { sin a, cos a, height }
{
    float octa = sdOctahedron(p, h);

    // Subtract bottom half
    return opS(octa, p.y);
}


float length_toPowNegative6(vec2 p)
{
    p = p * p * p;
    p = p * p;
    return hlsl_pow(p.x + p.y, 1.0 / 6.0);
}

float length_toPowNegative8(vec2 p)
{
    p = p * p; p = p * p; p = p * p;
    return hlsl_pow(p.x + p.y, 1.0 / 8.0);
}

float sdTorus82(vec3 p, vec2 t)
{
    vec2 q = vec2(length(p.xz) - t.x, p.y);
    return length_toPowNegative8(q) - t.y;
}

float sdTorus88(vec3 p, vec2 t)
{
    vec2 q = vec2(length_toPowNegative8(p.xz) - t.x, p.y);
    return length_toPowNegative8(q) - t.y;
}

float sdCylinder6(vec3 p, vec2 h)
{
    return hlsl_max(length_toPowNegative6(p.xz) - h.x, abs(p.y) - h.y);
}

vec3 sdCalculateNormal(in vec3 pos, in uint sdPrimitive)
{
    // PORT: DXC evaluates float2(1.0, -1.0) * 0.5773 * 0.0001 in float: 0.5773f * 0.0001f = 5.77299979e-05
    // (0x3872231D). glslang folds the literal product in double (5.77300016e-05, 1 ulp away), so the float
    // product is spelled as its bits.
    vec2 e = vec2(1.0, -1.0) * uintBitsToFloat(0x3872231Du);
    return normalize(
        e.xyy * GetDistanceFromSignedDistancePrimitive(pos + e.xyy, sdPrimitive) +
        e.yyx * GetDistanceFromSignedDistancePrimitive(pos + e.yyx, sdPrimitive) +
        e.yxy * GetDistanceFromSignedDistancePrimitive(pos + e.yxy, sdPrimitive) +
        e.xxx * GetDistanceFromSignedDistancePrimitive(pos + e.xxx, sdPrimitive));
}

#if defined(DXR_STAGE_CLOSEST_HIT) || defined(DXR_STAGE_ANY_HIT) || defined(DXR_STAGE_INTERSECTION) || \
    defined(DXR_RAY_EXTENT_OF_QUERY)
// Test ray against a signed distance primitive.
// Ref: https://www.scratchapixel.com/lessons/advanced-rendering/rendering-distance-fields/basic-sphere-tracer
// PORT: GLSL has no default arguments (HLSL: stepScale = 1.0f); the only caller passes it.
bool RaySignedDistancePrimitiveTest(in Ray ray, in uint sdPrimitive, inout float thit, inout ProceduralPrimitiveAttributes attr, in float stepScale)
{
    const float threshold = 0.0001;
    float t = RayTMin();
    const uint MaxSteps = 512;

    // Do sphere tracing through the AABB.
    uint i = 0;
    while (i++ < MaxSteps && t <= RayTCurrent())
    {
        vec3 position = ray.origin + t * ray.direction;
        float distance = GetDistanceFromSignedDistancePrimitive(position, sdPrimitive);

        // Has the ray intersected the primitive?
        if (distance <= threshold * t)
        {
            vec3 hitSurfaceNormal = sdCalculateNormal(position, sdPrimitive);
            if (IsAValidHit(ray, t, hitSurfaceNormal))
            {
                thit = t;
                attr.normal = hitSurfaceNormal;
                return true;
            }
        }

        // Since distance is the minimum distance to the primitive,
        // we can safely jump by that amount without intersecting the primitive.
        // We allow for scaling of steps per primitive type due to any pre-applied
        // transformations that don't preserve true distances.
        t += stepScale * distance;
    }
    return false;
}
#endif

// Analytically integrated checkerboard grid (box filter).
// Ref: http://iquilezles.org/www/articles/filterableprocedurals/filterableprocedurals.htm
// ratio - Center fill to border ratio.
float CheckersTextureBoxFilter(in vec2 uv, in vec2 dpdx, in vec2 dpdy, in uint ratio)
{
    vec2 w = hlsl_max(abs(dpdx), abs(dpdy));   // Filter kernel
    vec2 a = uv + 0.5*w;
    vec2 b = uv - 0.5*w;

    // Analytical integral (box filter).
    vec2 i = (floor(a) + hlsl_min(frac(a)*ratio, vec2(1.0)) -
        floor(b) - hlsl_min(frac(b)*ratio, vec2(1.0))) / (ratio*w);
    return (1.0 - i.x)*(1.0 - i.y);
}


#endif // SIGNEDDISTANCEPRIMITIVES_GLSL
