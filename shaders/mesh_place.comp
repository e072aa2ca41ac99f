#version 450
// First pass of the shaped ghosts' meshes cut on the GPU (ghosts::placeMesh, mesh_vertices.cpp;
// mesh_cells.comp cuts them): one work group per job (a ghost instance at one wavelength). Every
// decimation-th vertex of the ghost's grid, its attributes interpolated between the table's two angles
// around the light's (Catmull-Rom through four, folded where an outer one is missing; linear where a
// ray is lost at an outer one; a ray lost at one of the two is taken from the other up to the middle),
// placed in the frame's pixels (turned by the light's azimuth, mirrored), the iris's blades evaluated
// at its stop hits; then each vertex's Jacobian by central differences (one-sided at the border or
// next to a lost ray), and the job's extent and brightest pixel (shaped_mesh.cpp's brightestPixel).
//
// Per vertex S = 4 + C doubles in the job's slot of the scratch: pixel x, y, the weight (flux per cell,
// times decimation^2), the C constraints (apertures' margins, then the iris's blades per stop
// crossing, mm, >= 0 inside), the Jacobian (pixels^2 per cell). A lost vertex has x = NaN.

layout(local_size_x = LOCAL_SIZE) in;

const int kMaxConstraints = 40; // ghosts/mesh_clip.h

struct Instance {
    uint ghost;
    uint light;
    int a0; // between the table's angles a0 and a0 + 1
    int decimation;
    double t; // at this fraction
    double flatnessPx, edgeFlatnessPx, irradianceError;
};

struct Job {
    double xMin, xMax, yMin, yMax; // its placed vertices' extent, pixels
    double brightest;              // shaped_mesh.cpp's brightestPixel (weight per pixel^2)
    double flux; // the light's, at the job's wavelength
    double pad1, pad2;
    uint lit; // any vertex placed
    uint pad3, pad4, pad5;
    uint chunkPolys[LOCAL_SIZE]; // mesh_cells.comp: each invocation's first polygon and vertex in the job
    uint chunkVerts[LOCAL_SIZE];
};

layout(std430, binding = 0) readonly buffer TableData { float table[]; }; // every mesh's vertices
// Per ghost (grid, stride, apertures, stop crossings), then per (ghost, wavelength, angle) its mesh's
// first float in `table` (0xffffffff: a mesh without light).
layout(std430, binding = 1) readonly buffer TableIndex { uint tableIndex[]; };
layout(std430, binding = 2) readonly buffer Instances { Instance instances[]; };
// Per light: (cos, sin) of its azimuth, its mirrors (x, y), its flux (R, G), (B, 0), then the iris's
// blade normals turned and mirrored into the table's frame.
layout(std430, binding = 3) readonly buffer Lights { dvec2 lights[]; };
layout(std430, binding = 4) coherent buffer Scratch { double scratch[]; };
layout(std430, binding = 5) writeonly buffer Jobs { Job jobs[]; };

uniform int jobFirst; // this batch's first job (instance x channels + channel)
uniform int jobCount; // jobs in this batch (work groups past them return)
uniform int channels; // wavelengths drawn per instance
uniform int angles;   // the table's
uniform int ghosts;   // the table's
uniform int slot;     // doubles per job in the scratch
uniform int blades;   // the iris's edges (1: a circle)
uniform int width;
uniform int height;
uniform double pitch; // frame: mm per pixel and the sensor point at its centre
uniform double centreX;
uniform double centreY;
uniform double apothem; // the iris: its blades' distance from the axis, or its radius (a circle)

shared double sMin[LOCAL_SIZE], sMax[LOCAL_SIZE], tMin[LOCAL_SIZE], tMax[LOCAL_SIZE], sBright[LOCAL_SIZE],
    sAny[LOCAL_SIZE];

bool lost(float v) { return (floatBitsToUint(v) & 0x7fffffffu) > 0x7f800000u; }

dvec4 catmullRom(double u) {
    precise const double u2 = u * u, u3 = u2 * u;
    return 0.5LF * dvec4(-u + 2.0LF * u2 - u3, 2.0LF - 5.0LF * u2 + 3.0LF * u3, u + 4.0LF * u2 - 3.0LF * u3, -u2 + u3);
}

// Attribute z of the vertex at `src` of the meshes before (pb), at (p), after (q) and beyond (qa) the
// light's angle: the cubic through the four, or the line between the two at t.
double value(bool cubic, double t, dvec4 wc, uint src, uint pb, uint p, uint q, uint qa, uint z) {
    const uint a = src + z;
    precise double r;
    if (cubic)
        r = wc.x * double(table[pb + a]) + wc.y * double(table[p + a]) + wc.z * double(table[q + a]) +
            wc.w * double(table[qa + a]);
    else
        r = t == 0.0LF   ? double(table[p + a])
            : t == 1.0LF ? double(table[q + a])
                         : (1.0LF - t) * double(table[p + a]) + t * double(table[q + a]);
    return r;
}

void main() {
    const int job = jobFirst + int(gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x);
    if (job - jobFirst >= jobCount) return;
    const int lid = int(gl_LocalInvocationID.x);
    const Instance inst = instances[job / channels];
    const int w = job % channels;
    const uint g = inst.ghost;
    const int grid = int(tableIndex[4u * g]), stride = int(tableIndex[4u * g + 1u]);
    const int nA = int(tableIndex[4u * g + 2u]), crossings = int(tableIndex[4u * g + 3u]);
    const int dec = inst.decimation > 0 && grid % inst.decimation == 0 ? inst.decimation : 1;
    const int n = grid / dec, C = min(kMaxConstraints, nA + crossings * blades), S = 4 + C, J = 3 + C;
    const uint base = uint(job - jobFirst) * uint(slot);
    const int V = (n + 1) * (n + 1);

    // The four meshes around the light's angle (0xffffffff: none, or without light).
    const uint mesh = uint(4 * ghosts) + (g * uint(channels) + uint(w)) * uint(angles);
    const uint m0 = tableIndex[mesh + uint(inst.a0)], m1 = tableIndex[mesh + uint(min(inst.a0 + 1, angles - 1))];
    const uint mb = inst.a0 > 0 ? tableIndex[mesh + uint(inst.a0 - 1)] : 0xffffffffu;
    const uint ma = inst.a0 + 2 < angles ? tableIndex[mesh + uint(inst.a0 + 2)] : 0xffffffffu;
    precise dvec4 wc = catmullRom(inst.t);
    if (mb == 0xffffffffu) wc = dvec4(0.0, wc.y + 2.0LF * wc.x, wc.z - wc.x, wc.w);
    if (ma == 0xffffffffu) wc = dvec4(wc.x, wc.y - wc.w, wc.z + 2.0LF * wc.w, 0.0);

    const uint L = inst.light * uint(4 + (blades > 1 ? blades : 0));
    precise const dvec2 cs = lights[L], mirror = lights[L + 1u];
    const float nan = uintBitsToFloat(0x7fc00000u);

    for (int v = lid; v < V; v += LOCAL_SIZE) {
        const uint src = uint((v / (n + 1) * (grid + 1) + v % (n + 1)) * dec * stride);
        const uint o = base + uint(v * S);
        scratch[o] = double(nan);
        scratch[o + uint(J)] = double(nan);
        const bool p0 = m0 == 0xffffffffu || lost(table[m0 + src]), q0 = m1 == 0xffffffffu || lost(table[m1 + src]);
        precise double t = inst.t;
        if (p0 || q0) {
            if (p0 == q0 || p0 == (t < 0.5LF)) continue;
            t = p0 ? 1.0LF : 0.0LF;
        }
        const uint pb = mb != 0xffffffffu ? mb : m0, qa = ma != 0xffffffffu ? ma : m1;
        const bool cubic = t > 0.0LF && t < 1.0LF && !lost(table[pb + src]) && !lost(table[qa + src]);
        precise const double x = value(cubic, t, wc, src, pb, m0, m1, qa, 0u), y = value(cubic, t, wc, src, pb, m0, m1, qa, 1u);
        precise const double X = mirror.x * (cs.x * x - cs.y * y), Y = mirror.y * (cs.y * x + cs.x * y);
        precise double px = 0.5LF * double(width) + (X - centreX) / pitch;
        precise double py = 0.5LF * double(height) - (Y - centreY) / pitch;
        scratch[o] = px;
        scratch[o + 1u] = py;
        scratch[o + 2u] = double(dec) * double(dec) * value(cubic, t, wc, src, pb, m0, m1, qa, 2u);
        int k = 0;
        for (; k < nA && k < C; ++k) scratch[o + uint(3 + k)] = value(cubic, t, wc, src, pb, m0, m1, qa, uint(3 + k));
        for (int s = 0; s < crossings; ++s) {
            precise const double sx = value(cubic, t, wc, src, pb, m0, m1, qa, uint(3 + nA + 2 * s)),
                         sy = value(cubic, t, wc, src, pb, m0, m1, qa, uint(4 + nA + 2 * s));
            for (int b = 0; b < blades && k < C; ++b) {
                precise const dvec2 nb = lights[L + 4u + uint(b)];
                scratch[o + uint(3 + k++)] = blades > 1 ? apothem - (nb.x * sx + nb.y * sy) : apothem - sqrt(sx * sx + sy * sy);
            }
        }
    }
    memoryBarrierBuffer();
    barrier();

    // The Jacobians; the extent.
    precise double x0 = 1e300LF, x1 = -1e300LF, y0 = 1e300LF, y1 = -1e300LF;
    for (int v = lid; v < V; v += LOCAL_SIZE) {
        const uint o = base + uint(v * S);
        precise const double mx = scratch[o], my = scratch[o + 1u];
        if (isnan(mx)) continue;
        x0 = min(x0, mx), x1 = max(x1, mx), y0 = min(y0, my), y1 = max(y1, my);
        const int i = v % (n + 1), j = v / (n + 1);
        precise dvec2 d[2];
        for (int axis = 0; axis < 2; ++axis) {
            const int di = axis == 0 ? 1 : 0, dj = 1 - di;
            const bool hasLo = i - di >= 0 && j - dj >= 0, hasHi = i + di <= n && j + dj <= n;
            const uint lo = base + uint(((j - dj) * (n + 1) + i - di) * S), hi = base + uint(((j + dj) * (n + 1) + i + di) * S);
            const bool l = hasLo && !isnan(scratch[lo]), h = hasHi && !isnan(scratch[hi]);
            if (l && h)
                d[axis] = dvec2(0.5LF * (scratch[hi] - scratch[lo]), 0.5LF * (scratch[hi + 1u] - scratch[lo + 1u]));
            else if (h)
                d[axis] = dvec2(scratch[hi] - mx, scratch[hi + 1u] - my);
            else if (l)
                d[axis] = dvec2(mx - scratch[lo], my - scratch[lo + 1u]);
            else
                d[axis] = dvec2(double(nan));
        }
        precise double jacobian = d[0].x * d[1].y - d[0].y * d[1].x;
        scratch[o + uint(J)] = jacobian;
    }

    // The brightest pixel: the largest mean irradiance of a cell the apertures leave whole, over at
    // least a pixel; of any cell where none is whole.
    precise double whole = 0.0, anyCell = 0.0;
    for (int c = lid; c < n * n; c += LOCAL_SIZE) {
        const int i = c % n, j = c / n;
        const uint a = base + uint((j * (n + 1) + i) * S), b = a + uint(S), d = a + uint((n + 1) * S), e = d + uint(S);
        if (isnan(scratch[a]) || isnan(scratch[b]) || isnan(scratch[d]) || isnan(scratch[e])) continue;
        precise const double area = 0.5LF * abs((scratch[e] - scratch[a]) * (scratch[d + 1u] - scratch[b + 1u]) -
                                        (scratch[d] - scratch[b]) * (scratch[e + 1u] - scratch[a + 1u]));
        precise const double mean =
            0.25LF * (scratch[a + 2u] + scratch[b + 2u] + scratch[d + 2u] + scratch[e + 2u]) / max(area, 1.0LF);
        if (isnan(mean) || isinf(mean)) continue;
        bool inside = true;
        for (int k = 0; k < C && inside; ++k)
            inside = scratch[a + uint(3 + k)] >= 0.0LF && scratch[b + uint(3 + k)] >= 0.0LF &&
                     scratch[d + uint(3 + k)] >= 0.0LF && scratch[e + uint(3 + k)] >= 0.0LF;
        anyCell = max(anyCell, mean);
        if (inside) whole = max(whole, mean);
    }
    sMin[lid] = x0, sMax[lid] = x1, tMin[lid] = y0, tMax[lid] = y1, sBright[lid] = whole, sAny[lid] = anyCell;
    memoryBarrierShared();
    barrier();
    for (int step = LOCAL_SIZE / 2; step > 0; step /= 2) {
        if (lid < step) {
            sMin[lid] = min(sMin[lid], sMin[lid + step]);
            sMax[lid] = max(sMax[lid], sMax[lid + step]);
            tMin[lid] = min(tMin[lid], tMin[lid + step]);
            tMax[lid] = max(tMax[lid], tMax[lid + step]);
            sBright[lid] = max(sBright[lid], sBright[lid + step]);
            sAny[lid] = max(sAny[lid], sAny[lid + step]);
        }
        memoryBarrierShared();
        barrier();
    }
    if (lid == 0) {
        jobs[job - jobFirst].xMin = sMin[0];
        jobs[job - jobFirst].xMax = sMax[0];
        jobs[job - jobFirst].yMin = tMin[0];
        jobs[job - jobFirst].yMax = tMax[0];
        jobs[job - jobFirst].brightest = sBright[0] > 0.0LF ? sBright[0] : sAny[0];
        jobs[job - jobFirst].lit = sMax[0] >= sMin[0] ? 1u : 0u;
        precise const dvec2 f = lights[L + 2u + uint(w / 2)];
        jobs[job - jobFirst].flux = w % 2 == 0 ? f.x : f.y;
    }
}
