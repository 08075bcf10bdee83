// Ports VolumetricPrimitives.hlsli of microsoft/DirectX-Graphics-Samples@357ade6e,
// Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/VolumetricPrimitives.hlsli.
// Ray marching of Metaballs (aka "Blobs"). Intersection shaders only. Needs AnalyticPrimitives.glsl
// (RaySolidSphereIntersectionTest), as the HLSL gets it through ProceduralPrimitivesLibrary.hlsli.
#ifndef VOLUMETRICPRIMITIVESLIBRARY_GLSL
#define VOLUMETRICPRIMITIVESLIBRARY_GLSL

struct Metaball
{
    vec3 center;
    float  radius;
};

// Calculate a magnitude of an influence from a Metaball charge.
// Return metaball potential range: <0,1>
// mbRadius - largest possible area of metaball contribution - AKA its bounding sphere.
float CalculateMetaballPotential(in vec3 position, in Metaball blob, out float distance)
{
    distance = length(position - blob.center);

    if (distance <= blob.radius)
    {
        float d = distance;

        // Quintic polynomial field function.
        // The advantage of this polynomial is having smooth second derivative. Not having a smooth
        // second derivative may result in a sharp and visually unpleasant normal vector jump.
        // The field function should return 1 at distance 0 from a center, and 1 at radius distance,
        // but this one gives f(0) = 0, f(radius) = 1, so we use the distance to radius instead.
        d = blob.radius - d;

        float r = blob.radius;
        return 6 * (d*d*d*d*d) / (r*r*r*r*r)
            - 15 * (d*d*d*d) / (r*r*r*r)
            + 10 * (d*d*d) / (r*r*r);
    }
    return 0;
}

// Calculate field potential from all active metaballs.
float CalculateMetaballsPotential(in vec3 position, in Metaball blobs[N_METABALLS], in uint nActiveMetaballs)
{
    float sumFieldPotential = 0;
#if USE_DYNAMIC_LOOPS
    for (uint j = 0; j < nActiveMetaballs; j++)
#else
    for (uint j = 0; j < N_METABALLS; j++)
#endif
    {
        float dummy;
        sumFieldPotential += CalculateMetaballPotential(position, blobs[j], dummy);
    }
    return sumFieldPotential;
}

// Calculate a normal via central differences.
vec3 CalculateMetaballsNormal(in vec3 position, in Metaball blobs[N_METABALLS], in uint nActiveMetaballs)
{
    // A literal-only product: folded at full precision, then rounded (DXC and glslang agree: 5.77299988e-06; the float
    // product 0.5773f * 0.00001f happens to round to the same value).
    float e = 0.5773 * 0.00001;
    return normalize(vec3(
        CalculateMetaballsPotential(position + vec3(-e, 0, 0), blobs, nActiveMetaballs) -
        CalculateMetaballsPotential(position + vec3(e, 0, 0), blobs, nActiveMetaballs),
        CalculateMetaballsPotential(position + vec3(0, -e, 0), blobs, nActiveMetaballs) -
        CalculateMetaballsPotential(position + vec3(0, e, 0), blobs, nActiveMetaballs),
        CalculateMetaballsPotential(position + vec3(0, 0, -e), blobs, nActiveMetaballs) -
        CalculateMetaballsPotential(position + vec3(0, 0, e), blobs, nActiveMetaballs)));
}

void InitializeAnimatedMetaballs(out Metaball blobs[N_METABALLS], in float elapsedTime, in float cycleDuration)
{
    // Metaball centers at t0 and t1 key frames.
#if N_METABALLS == 5
    vec3 keyFrameCenters[N_METABALLS][2] =
    {
        { vec3(-0.7, 0, 0),vec3(0.7,0, 0) },
        { vec3(0.7 , 0, 0), vec3(-0.7, 0, 0) },
        { vec3(0, -0.7, 0),vec3(0, 0.7, 0) },
        { vec3(0, 0.7, 0), vec3(0, -0.7, 0) },
        { vec3(0, 0, 0),   vec3(0, 0, 0) }
    };
    // Metaball field radii of max influence
    float radii[N_METABALLS] = { 0.35, 0.35, 0.35, 0.35, 0.25 };
#else
    vec3 keyFrameCenters[N_METABALLS][2] =
    {
        { vec3(-0.3, -0.3, -0.4),vec3(0.3,-0.3,-0.0) },
        { vec3(0.0, -0.2, 0.5), vec3(0.0, 0.4, 0.5) },
        { vec3(0.4,0.4, 0.4), vec3(-0.4, 0.2, -0.4) }
    };
    // Metaball field radii of max influence
    float radii[N_METABALLS] = { 0.45, 0.55, 0.45 };
#endif

    // Calculate animated metaball center positions.
    float  tAnimate = CalculateAnimationInterpolant(elapsedTime, cycleDuration);
    for (uint j = 0; j < N_METABALLS; j++)
    {
        blobs[j].center = lerp(keyFrameCenters[j][0], keyFrameCenters[j][1], tAnimate);
        blobs[j].radius = radii[j];
    }
}

// Find all metaballs that ray intersects.
// The passed in array is sorted to the first nActiveMetaballs.
void FindIntersectingMetaballs(in Ray ray, out float tmin, out float tmax, inout Metaball blobs[N_METABALLS], out uint nActiveMetaballs)
{
    // Find the entry and exit points for all metaball bounding spheres combined.
    tmin = INFINITY;
    tmax = -INFINITY;

    nActiveMetaballs = 0;
    for (uint i = 0; i < N_METABALLS; i++)
    {
        float _thit, _tmax;
        if (RaySolidSphereIntersectionTest(ray, _thit, _tmax, blobs[i].center, blobs[i].radius))
        {
            tmin = hlsl_min(_thit, tmin);
            tmax = hlsl_max(_tmax, tmax);
#if LIMIT_TO_ACTIVE_METABALLS
            blobs[nActiveMetaballs++] = blobs[i];
#else
            nActiveMetaballs = N_METABALLS;
#endif
        }
    }
    tmin = hlsl_max(tmin, RayTMin());
    tmax = hlsl_min(tmax, RayTCurrent());
}

// Test if a ray with RayFlags and segment <RayTMin(), RayTCurrent()> intersects metaball field.
// The test sphere traces through the metaball field until it hits a threshold isosurface.
bool RayMetaballsIntersectionTest(in Ray ray, inout float thit, inout ProceduralPrimitiveAttributes attr, in float elapsedTime)
{
    Metaball blobs[N_METABALLS];
    InitializeAnimatedMetaballs(blobs, elapsedTime, 12.0f);

    float tmin, tmax;   // Ray extents to first and last metaball intersections.
    uint nActiveMetaballs = 0;  // Number of metaballs's that the ray intersects.
    FindIntersectingMetaballs(ray, tmin, tmax, blobs, nActiveMetaballs);

    uint MAX_STEPS = 128;
    float t = tmin;
    float minTStep = (tmax - tmin) / (MAX_STEPS / 1);
    uint iStep = 0;

    while (iStep++ < MAX_STEPS)
    {
        vec3 position = ray.origin + t * ray.direction;
        float fieldPotentials[N_METABALLS];    // Field potentials for each metaball.
        float sumFieldPotential = 0;           // Sum of all metaball field potentials.

        // Calculate field potentials from all metaballs.
#if USE_DYNAMIC_LOOPS
        for (uint j = 0; j < nActiveMetaballs; j++)
#else
        for (uint j = 0; j < N_METABALLS; j++)
#endif
        {
            float distance;
            fieldPotentials[j] = CalculateMetaballPotential(position, blobs[j], distance);
            sumFieldPotential += fieldPotentials[j];
         }

        // Field potential threshold defining the isosurface.
        // Threshold - valid range is (0, 1>, the larger the threshold the smaller the blob.
        const float Threshold = 0.25f;

        // Have we crossed the isosurface?
        if (sumFieldPotential >= Threshold)
        {
            vec3 normal = CalculateMetaballsNormal(position, blobs, nActiveMetaballs);
            if (IsAValidHit(ray, t, normal))
            {
                thit = t;
                attr.normal = normal;
                return true;
            }
        }
        t += minTStep;
    }

    return false;
}

#endif // VOLUMETRICPRIMITIVESLIBRARY_GLSL
