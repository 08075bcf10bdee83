// Ports SignedDistanceFractals.hlsli of microsoft/DirectX-Graphics-Samples@357ade6e,
// Samples/Desktop/D3D12Raytracing/src/D3D12RaytracingProceduralGeometry/SignedDistanceFractals.hlsli.
// Set of signed distance fractal tests. Needs SignedDistancePrimitives.glsl (sdPyramid).
#ifndef SIGNEDDISTANCEFRACTALS_GLSL
#define SIGNEDDISTANCEFRACTALS_GLSL

//------------------------------------------------------------------

// Returns a signed distance to a recursive pyramid fractal.
// h = { sin a, cos a, height of a pyramid}.
// a = pyramid's inner angle between its side plane and a ground plane.
// Pyramid position - sitting on a ground plane.
// Pyramid span: {<-a,0,-a>, <a,h.z,a>}, where a = width of base = h.z * h.y / h.x.
// More info here http://blog.hvidtfeldts.net/index.php/2011/08/distance-estimated-3d-fractals-iii-folding-space/
// PORT: GLSL has no default arguments (HLSL: Scale = 2.0f); the only caller passes 2.0f.
float sdFractalPyramid(in vec3 position, vec3 h, in float Scale)
{
    // Set pyramid vertices to AABB's extremities.
    float a = h.z * h.y / h.x;
    vec3 v1 = vec3(0, h.z, 0);
    vec3 v2 = vec3(-a, 0, a);
    vec3 v3 = vec3(a, 0, -a);
    vec3 v4 = vec3(a, 0, a);
    vec3 v5 = vec3(-a, 0, -a);

    int n = 0;
    for (n = 0; n < N_FRACTAL_ITERATIONS; n++)
    {
        // Find the closest vertex.
        float dist, d;
        vec3 v;
        v = v1; dist = length_toPow2(position - v1);
        d = length_toPow2(position - v2); if (d < dist) { v = v2; dist = d; }
        d = length_toPow2(position - v3); if (d < dist) { v = v3; dist = d; }
        d = length_toPow2(position - v4); if (d < dist) { v = v4; dist = d; }
        d = length_toPow2(position - v5); if (d < dist) { v = v5; dist = d; }

        // Update to a relative position in the current fractal iteration.
        position = Scale * position - v * (Scale - 1.0);
    }
    float distance = sdPyramid(position, h);

    // Convert the distance from within a fractal iteration to the object space.
    return distance * hlsl_pow(Scale, float(-n));
}
#endif // SIGNEDDISTANCEFRACTALS_GLSL
