#include "emulator/intersection.h"

#include <cmath>
#include <utility>

namespace refray::dxr {

namespace {

int largestAxis(vec3 d) {
    const float ax = std::fabs(d.x), ay = std::fabs(d.y), az = std::fabs(d.z);
    if (ax > ay) return ax > az ? 0 : 2;
    return ay > az ? 1 : 2;
}

// Top-left style ownership of an edge whose edge function is exactly zero. (dx, dy) is
// the edge direction in the sheared 2D frame, already multiplied by the triangle's
// orientation sign, so two triangles sharing the edge see opposite directions and
// exactly one of them owns it.
bool ownsEdge(double dx, double dy, bool alternate) {
    if (alternate) return dy < 0.0 || (dy == 0.0 && dx > 0.0);
    return dy > 0.0 || (dy == 0.0 && dx < 0.0);
}

}  // namespace

std::optional<TriangleIntersection> intersectTriangle(vec3 org, vec3 dir, vec3 v0, vec3 v1, vec3 v2,
                                                      bool alternateEdgeRule) {
    // Permute axes so z is the largest direction component; swap x/y to keep winding.
    const int kz = largestAxis(dir);
    int kx = (kz + 1) % 3, ky = (kx + 1) % 3;
    if (dir[kz] == 0.0f || std::isnan(dir[kz])) return std::nullopt;
    if (dir[kz] < 0.0f) std::swap(kx, ky);
    const float Sx = dir[kx] / dir[kz], Sy = dir[ky] / dir[kz], Sz = 1.0f / dir[kz];

    const vec3 A = v0 - org, B = v1 - org, C = v2 - org;
    const float Ax = A[kx] - Sx * A[kz], Ay = A[ky] - Sy * A[kz];
    const float Bx = B[kx] - Sx * B[kz], By = B[ky] - Sy * B[kz];
    const float Cx = C[kx] - Sx * C[kz], Cy = C[ky] - Sy * C[kz];

    double U = double(Cx * By - Cy * Bx);
    double V = double(Ax * Cy - Ay * Cx);
    double W = double(Bx * Ay - By * Ax);
    if (U == 0.0 || V == 0.0 || W == 0.0) {
        // Exactly on an edge in float: decide in double, which is exact for float inputs.
        U = double(Cx) * double(By) - double(Cy) * double(Bx);
        V = double(Ax) * double(Cy) - double(Ay) * double(Cx);
        W = double(Bx) * double(Ay) - double(By) * double(Ax);
    }
    if ((U < 0.0 || V < 0.0 || W < 0.0) && (U > 0.0 || V > 0.0 || W > 0.0)) return std::nullopt;
    // DEGEN-7: a triangle with collinear vertices is inactive. For oblique rays the float shear above can round
    // such a triangle into a sliver with a non-zero determinant, so zero area is decided from the vertices
    // themselves (in double; only rays that passed the edge tests pay for it).
    const glm::dvec3 area = glm::cross(glm::dvec3(v1) - glm::dvec3(v0), glm::dvec3(v2) - glm::dvec3(v0));
    if (area.x == 0.0 && area.y == 0.0 && area.z == 0.0) return std::nullopt;
    const double det = U + V + W;
    if (det == 0.0 || std::isnan(det)) return std::nullopt;

    // Edge ownership where the ray passes exactly through an edge or vertex.
    const double orientation = det > 0.0 ? 1.0 : -1.0;
    if (U == 0.0 && !ownsEdge(orientation * (double(Cx) - Bx), orientation * (double(Cy) - By), alternateEdgeRule))
        return std::nullopt;
    if (V == 0.0 && !ownsEdge(orientation * (double(Ax) - Cx), orientation * (double(Ay) - Cy), alternateEdgeRule))
        return std::nullopt;
    if (W == 0.0 && !ownsEdge(orientation * (double(Bx) - Ax), orientation * (double(By) - Ay), alternateEdgeRule))
        return std::nullopt;

    const double Az = double(Sz) * A[kz], Bz = double(Sz) * B[kz], Cz = double(Sz) * C[kz];
    const double T = U * Az + V * Bz + W * Cz;
    TriangleIntersection hit;
    hit.t = float(T / det);
    hit.barycentrics = vec2(float(V / det), float(W / det));
    return hit;
}

std::optional<SlabInterval> intersectAABB(vec3 origin, vec3 direction, const RaytracingAABB& box, float tMin,
                                          float tMax) {
    const float lo[3] = {box.MinX, box.MinY, box.MinZ};
    const float hi[3] = {box.MaxX, box.MaxY, box.MaxZ};
    float tEnter = tMin, tExit = tMax;
    for (int axis = 0; axis < 3; ++axis) {
        const float o = origin[axis], d = direction[axis];
        if (d == 0.0f) {
            // Parallel to the slab (either sign of zero): inside iff the origin is.
            if (o < lo[axis] || o > hi[axis]) return std::nullopt;
            continue;
        }
        float t0 = (lo[axis] - o) / d, t1 = (hi[axis] - o) / d;
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > tEnter) tEnter = t0;
        if (t1 < tExit) tExit = t1;
        if (!(tEnter <= tExit)) return std::nullopt;
    }
    return SlabInterval{tEnter, tExit};
}

}  // namespace refray::dxr
