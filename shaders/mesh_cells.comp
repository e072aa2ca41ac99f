#version 450
// Second and third passes of the shaped ghosts' meshes cut on the GPU: one work group per job, each
// invocation every LOCAL_SIZE-th cell of the mesh from its own (neighbouring invocations take
// neighbouring cells: like work, adjacent in the scratch), cut as ghosts::meshPolygons' CellCutter
// does (shaped_mesh.cpp): k x k sub-cells placed by the bicubic (Catmull-Rom) surface through the
// 4 x 4 vertices around the cell (bilinear where it leaves the grid or meets a lost ray), k the
// largest of the flatness rule (the landing points and the aperture edges within the job's tolerance
// of the plane sub-cells) and the irradiance rule (the elements' density within the job's error);
// each sub-cell's two triangles clipped by the constraints that change sign over them, with their
// mean weight x lit share of the pupil area as energy and, for linear elements, the plane through
// their vertices' irradiances as the density's gradient. Pass 0 counts each invocation's polygons
// and vertices and scans them (the jobs' totals are scanned by bin_scan.comp); pass 1 runs the same
// instructions and writes the polygons where the scans say, in the binned raster's layout
// (polygon_bins.comp), and each job's energy and covered area. The layout does not depend on
// scheduling.

layout(local_size_x = LOCAL_SIZE) in;

const int kMaxConstraints = 40;              // ghosts/mesh_clip.h
const int kMaxPolygon = kMaxConstraints + 3; // vertices of a clipped triangle
const double kLinearMinAreaPx = 1.0LF;       // shaped_mesh.cpp
const double kIrradianceSubcellPx = 0.25LF;

struct Instance {
    uint ghost;
    uint light;
    int a0;
    int decimation;
    double t;
    double flatnessPx, edgeFlatnessPx, irradianceError;
};

struct Job {
    double xMin, xMax, yMin, yMax;
    double brightest;
    double flux; // the light's, at the job's wavelength
    double pad1, pad2;
    uint lit;
    uint pad3, pad4, pad5;
    uint chunkPolys[LOCAL_SIZE];
    uint chunkVerts[LOCAL_SIZE];
};

struct Polygon { // polygon_bins.comp's
    uint first;
    uint count;
    uint channel;
    uint splat;
    double energy;
    double gx, gy;
};

layout(std430, binding = 0) writeonly buffer OutVertices { vec2 outVertices[]; };
layout(std430, binding = 1) readonly buffer TableIndex { uint tableIndex[]; };
layout(std430, binding = 2) readonly buffer Instances { Instance instances[]; };
layout(std430, binding = 3) writeonly buffer OutPolygons { Polygon outPolygons[]; };
layout(std430, binding = 4) readonly buffer Scratch { double scratch[]; };
layout(std430, binding = 5) buffer Jobs { Job jobs[]; };
// Pass 0: each job's polygons at [job], vertices at [vertsAt + job]; pass 1: their exclusive scans.
layout(std430, binding = 6) buffer JobCounts { uint jobCounts[]; };
layout(std430, binding = 7) writeonly buffer JobStats { dvec2 jobStats[]; }; // (energy, area in pixels)

uniform int pass;
uniform int jobFirst;
uniform int jobCount; // jobs in this batch (work groups past them return)
uniform int channels;
uniform int slot;
uniform int blades;
uniform int vertsAt;
uniform int width;
uniform int height;
uniform int maxSubdivision;
uniform int linearDensity;
uniform double subcellPx;
uniform float splatBelow; // > 0: a polygon narrower than this on both axes is splatted (renderShaped's grid)

// The job.
uint base;
int n, C, S, J;
double flux, flatness, edgeFlatness, tolerance;
int kEdge;
int channel;
// The current cell: its 4 x 4 neighbourhood (scratch offsets), its corners (00, 10, 01, 11).
uint nb[16];
uint corner[4];
// Vertices of the current (sub-)cell, in slots 0..3 (00, 10, 01, 11): pixel x, y, weight and
// Jacobian, and how their constraints are read (constraint()): a corner of the cell (mode 0, wa.x),
// the bicubic at weights (wa, wb) (mode 1) or the bilinear at (u, v) = wa.xy (mode 2). Constraints are
// evaluated where they are needed rather than stored: private memory stays small.
dvec4 V[4];
int slotMode[4];
dvec4 slotWa[4], slotWb[4];
// The clipper's polygons (barycentrics of P, Q, R: (b0, b1, b2)) and the constraints cutting the triangle.
dvec3 clipA[kMaxPolygon], clipB[kMaxPolygon];
int clipCount;
int cuts[kMaxConstraints];
// What the invocation adds: polygons, vertices, energy, area; where pass 1 writes.
uint polys, verts, polyCursor, vertCursor, polyEnd, vertEnd;
double energySum, areaSum;

dvec4 catmullRom(double u) {
    precise const double u2 = u * u, u3 = u2 * u;
    return 0.5LF * dvec4(-u + 2.0LF * u2 - u3, 2.0LF - 5.0LF * u2 + 3.0LF * u3, u + 4.0LF * u2 - 3.0LF * u3, -u2 + u3);
}

dvec4 catmullRomSlope(double u) {
    precise const double u2 = u * u;
    return 0.5LF * dvec4(-1.0LF + 4.0LF * u - 3.0LF * u2, -10.0LF * u + 9.0LF * u2, 1.0LF + 8.0LF * u - 9.0LF * u2,
                         -2.0LF * u + 3.0LF * u2);
}

bool finite(double v) { return !isnan(v) && !isinf(v); }

double at(uint v, int z) { return scratch[v + uint(z)]; }

double bicubic(dvec4 wx, dvec4 wy, int z) {
    precise double acc = 0.0;
    for (int q = 0; q < 4; ++q)
        acc += wy[q] * (wx.x * at(nb[q * 4], z) + wx.y * at(nb[q * 4 + 1], z) + wx.z * at(nb[q * 4 + 2], z) +
                        wx.w * at(nb[q * 4 + 3], z));
    return acc;
}

double cellAreaPx(double ax, double ay, double bx, double by, double dx, double dy, double ex, double ey) {
    precise double area = 0.5LF * abs((ex - ax) * (dy - by) - (dx - bx) * (ey - ay));
    return area;
}

// The sub-cells per side that the cell's irradiance asks for (shaped_mesh.cpp's irradianceSplit).
int irradianceSplit(dvec4 r, double centre, bool fold, double areaPx, double sizePx) {
    const int cap = clamp(int(ceil(sizePx / kIrradianceSubcellPx)), 1, maxSubdivision);
    precise double lo = 1e300LF, hi = 0.0;
    for (int q = 0; q < 5; ++q) {
        precise const double v = q < 4 ? r[q] : centre;
        if (finite(v)) lo = min(lo, v), hi = max(hi, v);
    }
    precise const double spread = fold ? hi : max(0.0LF, hi - lo);
    precise const double dev = max(abs(centre - 0.5LF * (r.x + r.w)), abs(centre - 0.5LF * (r.y + r.z)));
    for (int k = 1; k < cap; ++k) {
        precise const double h = sizePx / double(k);
        const bool slope = linearDensity != 0 && !fold && areaPx >= 2.0LF * kLinearMinAreaPx * double(k) * double(k);
        precise const double err = slope ? dev / (double(k) * double(k)) : 0.5LF * spread / double(k) * min(1.0LF, h);
        if (err <= tolerance) return k;
    }
    return cap;
}

// Sub-cells per side for a cell whose four corners land (CellCutter::subdivision).
int subdivision(bool cubic) {
    precise double cx0 = at(corner[0], 0), cx1 = cx0, cy0 = at(corner[0], 1), cy1 = cy0;
    for (int q = 1; q < 4; ++q) {
        cx0 = min(cx0, at(corner[q], 0)), cx1 = max(cx1, at(corner[q], 0));
        cy0 = min(cy0, at(corner[q], 1)), cy1 = max(cy1, at(corner[q], 1));
    }
    precise const double reach = 1.0LF + max(cx1 - cx0, cy1 - cy0);
    if (cx1 < -reach || cy1 < -reach || cx0 > double(width) + reach || cy0 > double(height) + reach) return 1;
    precise const dvec4 mid = catmullRom(0.5LF), midSlope = catmullRomSlope(0.5LF);
    precise double landing = 0.0;
    if (cubic)
        for (int z = 0; z < 2; ++z) {
            precise const double plane = 0.25LF * (at(corner[0], z) + at(corner[1], z) + at(corner[2], z) + at(corner[3], z));
            landing = max(landing, abs(bicubic(mid, mid, z) - plane));
        }
    precise const double sizePx = max(max(abs(at(corner[3], 0) - at(corner[0], 0)), abs(at(corner[1], 0) - at(corner[2], 0))),
                              max(abs(at(corner[3], 1) - at(corner[0], 1)), abs(at(corner[1], 1) - at(corner[2], 1))));
    bool edge = false;
    precise double edgeDev = 0.0;
    for (int k = 0; k < C; ++k) {
        const int z = 3 + k;
        precise const double a = at(corner[0], z), b = at(corner[1], z), d = at(corner[2], z), e = at(corner[3], z);
        precise const double lo = min(min(a, b), min(d, e)), hi = max(max(a, b), max(d, e));
        if (!(lo < 0.0LF && hi >= 0.0LF)) continue;
        edge = true;
        if (cubic) {
            precise const double plane = 0.25LF * (a + b + d + e);
            edgeDev = max(edgeDev, abs(bicubic(mid, mid, z) - plane) * sizePx / (hi - lo));
        }
    }
    if (edge && !cubic) return kEdge;
    precise const double edgeTol = edgeFlatness > 0.0LF ? edgeFlatness : flatness;
    int K = clamp(int(ceil(sqrt(max(landing / flatness, edgeDev / edgeTol)))), 1, maxSubdivision);
    if (cubic && sizePx > 0.0LF && tolerance > 0.0LF && finite(tolerance)) {
        precise const double areaPx = cellAreaPx(at(corner[0], 0), at(corner[0], 1), at(corner[1], 0), at(corner[1], 1),
                                         at(corner[2], 0), at(corner[2], 1), at(corner[3], 0), at(corner[3], 1));
        precise const double jc = bicubic(midSlope, mid, 0) * bicubic(mid, midSlope, 1) -
                          bicubic(mid, midSlope, 0) * bicubic(midSlope, mid, 1);
        precise const double centre = max(0.0LF, bicubic(mid, mid, 2)) / abs(jc);
        bool positive = jc > 0.0LF, negative = jc < 0.0LF;
        precise dvec4 r;
        for (int q = 0; q < 4; ++q) {
            precise const double jq = at(corner[q], J);
            r[q] = max(0.0LF, at(corner[q], 2)) / abs(jq);
            positive = positive && jq > 0.0LF;
            negative = negative && jq < 0.0LF;
        }
        K = max(K, irradianceSplit(r, centre, !(positive || negative), areaPx, sizePx));
    }
    return K;
}

// Constraint k at slot s's vertex.
double constraint(int s, int k) {
    const int z = 3 + k;
    if (slotMode[s] == 0) return at(corner[int(slotWa[s].x)], z);
    if (slotMode[s] == 1) return bicubic(slotWa[s], slotWb[s], z);
    precise const double u = slotWa[s].x, v = slotWa[s].y;
    precise double r = (1.0LF - v) * ((1.0LF - u) * at(corner[0], z) + u * at(corner[1], z)) +
                       v * ((1.0LF - u) * at(corner[2], z) + u * at(corner[3], z));
    return r;
}

// Corner q of the cell into slot s.
void cornerVertex(int q, int s) {
    V[s] = dvec4(at(corner[q], 0), at(corner[q], 1), at(corner[q], 2), at(corner[q], J));
    slotMode[s] = 0;
    slotWa[s] = dvec4(double(q));
}

// Sub-vertex (a, b) of K per side into slot s.
void subVertex(int a, int b, int K, bool cubic, int s) {
    if (cubic) {
        precise const dvec4 ca = catmullRom(double(a) / double(K)), cb = catmullRom(double(b) / double(K));
        precise const dvec4 sa = catmullRomSlope(double(a) / double(K)), sb = catmullRomSlope(double(b) / double(K));
        precise double jacobian = bicubic(sa, cb, 0) * bicubic(ca, sb, 1) - bicubic(ca, sb, 0) * bicubic(sa, cb, 1);
        V[s] = dvec4(bicubic(ca, cb, 0), bicubic(ca, cb, 1), bicubic(ca, cb, 2), jacobian);
        slotMode[s] = 1;
        slotWa[s] = ca;
        slotWb[s] = cb;
        return;
    }
    precise const double u = double(a) / double(K), v = double(b) / double(K);
    precise double o[3], du[2], dv[2];
    for (int z = 0; z < 3; ++z)
        o[z] = (1.0LF - v) * ((1.0LF - u) * at(corner[0], z) + u * at(corner[1], z)) +
               v * ((1.0LF - u) * at(corner[2], z) + u * at(corner[3], z));
    for (int z = 0; z < 2; ++z) {
        du[z] = (1.0LF - v) * (at(corner[1], z) - at(corner[0], z)) + v * (at(corner[3], z) - at(corner[2], z));
        dv[z] = (1.0LF - u) * (at(corner[2], z) - at(corner[0], z)) + u * (at(corner[3], z) - at(corner[1], z));
    }
    precise double jacobian = du[0] * dv[1] - dv[0] * du[1];
    V[s] = dvec4(o[0], o[1], o[2], jacobian);
    slotMode[s] = 2;
    slotWa[s] = dvec4(u, v, 0.0, 0.0);
}

// The triangle's density's gradient relative to its value at `c` (CellCutter::gradientOf).
dvec2 gradientOf(int P, int Q, int R, dvec2 c) {
    if (linearDensity == 0) return dvec2(0.0);
    precise const double jP = V[P].w, jQ = V[Q].w, jR = V[R].w;
    if (!(jP * jQ > 0.0LF && jP * jR > 0.0LF)) return dvec2(0.0);
    precise const double rP = max(0.0LF, V[P].z) / abs(jP), rQ = max(0.0LF, V[Q].z) / abs(jQ),
                 rR = max(0.0LF, V[R].z) / abs(jR);
    precise const dvec2 e1 = dvec2(V[Q].x - V[P].x, V[Q].y - V[P].y), e2 = dvec2(V[R].x - V[P].x, V[R].y - V[P].y);
    precise const double det = e1.x * e2.y - e1.y * e2.x;
    if (!(abs(det) >= 2.0LF * kLinearMinAreaPx)) return dvec2(0.0);
    precise const dvec2 grad =
        dvec2(((rQ - rP) * e2.y - (rR - rP) * e1.y) / det, ((rR - rP) * e1.x - (rQ - rP) * e2.x) / det);
    precise const double value = rP + grad.x * (c.x - V[P].x) + grad.y * (c.y - V[P].y);
    if (!(value > 0.0LF) || !finite(grad.x) || !finite(grad.y)) return dvec2(0.0);
    return grad / value;
}

// The pixel position of the clipped polygon's vertex q (barycentrics of the triangle P, Q, R).
dvec2 clipped(int q, int P, int Q, int R) {
    precise const dvec3 b = clipA[q];
    precise dvec2 p = dvec2(b.x * V[P].x + b.y * V[Q].x + b.z * V[R].x, b.x * V[P].y + b.y * V[Q].y + b.z * V[R].y);
    return p;
}

// Adds the clipped polygon clipA[0 .. clipCount) of the triangle P, Q, R with energy e
// (ShapedPolygons::add); pass 1 writes it.
void emit(int P, int Q, int R, double e, dvec2 gradient) {
    const int count = clipCount;
    precise double area2 = 0.0;
    for (int i = 0; i < count; ++i) {
        precise const dvec2 p = clipped(i, P, Q, R), q = clipped((i + 1) % count, P, Q, R);
        area2 += p.x * q.y - q.x * p.y;
    }
    if (finite(area2)) areaSum += 0.5LF * abs(area2);
    energySum += e;
    ++polys;
    verts += uint(count);
    if (pass == 1 && polyCursor < polyEnd && vertCursor + uint(count) <= vertEnd) {
        // Its extent as renderShaped's splat rule reads it: rows from the float vertices, columns in
        // double from them.
        float yMin = 1e30, yMax = -1e30;
        double xMin = 1e300LF, xMax = -1e300LF;
        for (int i = 0; i < count; ++i) {
            const vec2 v = vec2(clipped(i, P, Q, R));
            outVertices[vertCursor + uint(i)] = v;
            yMin = min(yMin, v.y), yMax = max(yMax, v.y);
            xMin = min(xMin, double(v.x)), xMax = max(xMax, double(v.x));
        }
        const bool splat = splatBelow > 0.0 && yMax - yMin < splatBelow && xMax - xMin < double(splatBelow);
        // The gradient as the CPU stores it (float).
        const vec2 g = vec2(gradient);
        outPolygons[polyCursor] =
            Polygon(vertCursor, uint(count), uint(channel), splat ? 1u : 0u, e, double(g.x), double(g.y));
        ++polyCursor;
        vertCursor += uint(count);
    }
}

// Clips the triangle (barycentrics) by the first m constraints of `cuts` (TriangleClipper::clip); the lit
// share of its area, the polygon left in clipA[0 .. clipCount).
double clip(int m, int P, int Q, int R) {
    clipCount = 3;
    clipA[0] = dvec3(1.0, 0.0, 0.0);
    clipA[1] = dvec3(0.0, 1.0, 0.0);
    clipA[2] = dvec3(0.0, 0.0, 1.0);
    for (int k = 0; k < m && clipCount > 0; ++k) {
        precise const dvec3 ck = dvec3(constraint(P, cuts[k]), constraint(Q, cuts[k]), constraint(R, cuts[k]));
        int kept = 0;
        for (int p = 0; p < clipCount; ++p) {
            precise const dvec3 A = clipA[p], B = clipA[(p + 1) % clipCount];
            precise const double va = A.x * ck.x + A.y * ck.y + A.z * ck.z;
            precise const double vb = B.x * ck.x + B.y * ck.y + B.z * ck.z;
            if (va >= 0.0LF && kept < kMaxPolygon) clipB[kept++] = A;
            if ((va >= 0.0LF) != (vb >= 0.0LF) && kept < kMaxPolygon) {
                precise dvec3 cut = A + (B - A) * (va / (va - vb));
                clipB[kept++] = cut;
            }
        }
        for (int p = 0; p < kept; ++p) clipA[p] = clipB[p];
        clipCount = kept;
    }
    if (clipCount < 3) return 0.0;
    precise double area = 0.0;
    for (int p = 0; p < clipCount; ++p) {
        precise const dvec3 A = clipA[p], B = clipA[(p + 1) % clipCount];
        area += A.y * B.z - B.y * A.z;
    }
    return clamp(abs(area), 0.0LF, 1.0LF);
}

// The triangle of vertices V[P], V[Q], V[R] (pupil area `area` cells), clipped (CellCutter::triangle).
void triangle(int P, int Q, int R, double area) {
    precise const double e = flux * area * (V[P].z + V[Q].z + V[R].z) / 3.0LF;
    if (!(e > 0.0LF)) return;
    int m = 0;
    for (int k = 0; k < C; ++k) {
        precise const double a = constraint(P, k), b = constraint(Q, k), d = constraint(R, k);
        if (a < 0.0LF && b < 0.0LF && d < 0.0LF) return;
        if (a < 0.0LF || b < 0.0LF || d < 0.0LF) cuts[m++] = k;
    }
    if (m == 0) {
        clipCount = 3;
        clipA[0] = dvec3(1.0, 0.0, 0.0), clipA[1] = dvec3(0.0, 1.0, 0.0), clipA[2] = dvec3(0.0, 0.0, 1.0);
        precise const dvec2 c = (dvec2(V[P].xy) + dvec2(V[Q].xy) + dvec2(V[R].xy)) / 3.0LF;
        emit(P, Q, R, e, gradientOf(P, Q, R, c));
        return;
    }
    precise const double share = clip(m, P, Q, R);
    if (share <= 0.0LF) return;
    // The centroid of what is drawn.
    precise double a = 0.0;
    precise dvec2 sum = dvec2(0.0);
    for (int k = 0; k < clipCount; ++k) {
        precise const dvec2 u = clipped(k, P, Q, R), v = clipped((k + 1) % clipCount, P, Q, R);
        precise const double cross = u.x * v.y - v.x * u.y;
        a += cross;
        sum += (u + v) * cross;
    }
    precise const dvec2 c = a != 0.0LF ? sum / (3.0LF * a) : clipped(0, P, Q, R);
    emit(P, Q, R, e * share, gradientOf(P, Q, R, c));
}

bool ok(int i, int j) { return !isnan(scratch[base + uint((j * (n + 1) + i) * S)]); }

void cell(int i, int j) {
    const bool c0 = ok(i, j), c1 = ok(i + 1, j), c2 = ok(i, j + 1), c3 = ok(i + 1, j + 1);
    const bool all = c0 && c1 && c2 && c3;
    corner[0] = base + uint((j * (n + 1) + i) * S);
    corner[1] = corner[0] + uint(S);
    corner[2] = corner[0] + uint((n + 1) * S);
    corner[3] = corner[2] + uint(S);
    bool cubic = all;
    for (int q = -1; q <= 2 && cubic; ++q)
        for (int r = -1; r <= 2 && cubic; ++r) {
            const int x = i + r, y = j + q;
            if (x < 0 || y < 0 || x > n || y > n || !ok(x, y))
                cubic = false;
            else
                nb[(q + 1) * 4 + (r + 1)] = base + uint((y * (n + 1) + x) * S);
        }
    if (all)
        for (int k = 0; k < C; ++k)
            if (at(corner[0], 3 + k) < 0.0LF && at(corner[1], 3 + k) < 0.0LF && at(corner[2], 3 + k) < 0.0LF &&
                at(corner[3], 3 + k) < 0.0LF)
                return;
    const int K = all ? subdivision(cubic) : 1;
    if (K == 1) {
        for (int q = 0; q < 4; ++q) cornerVertex(q, q);
        // mesh_clip.h's cellTriangles: split along the diagonal that keeps a triangle when one
        // corner is lost.
        if (c0 && c3) {
            if (c1) triangle(0, 1, 3, 0.5LF);
            if (c2) triangle(0, 3, 2, 0.5LF);
        } else {
            if (c0 && c1 && c2) triangle(0, 1, 2, 0.5LF);
            if (c1 && c2 && c3) triangle(1, 3, 2, 0.5LF);
        }
        return;
    }
    precise const double subArea = 0.5LF / (double(K) * double(K));
    for (int b = 0; b < K; ++b)
        for (int a = 0; a < K; ++a) {
            subVertex(a, b, K, cubic, 0);
            subVertex(a + 1, b, K, cubic, 1);
            subVertex(a, b + 1, K, cubic, 2);
            subVertex(a + 1, b + 1, K, cubic, 3);
            triangle(0, 1, 3, subArea);
            triangle(0, 3, 2, subArea);
        }
}

shared uint sPolys[LOCAL_SIZE], sVerts[LOCAL_SIZE];
shared double sEnergy[LOCAL_SIZE], sArea[LOCAL_SIZE];

void main() {
    const int job = jobFirst + int(gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x);
    const int local = job - jobFirst;
    if (local >= jobCount) return;
    const int lid = int(gl_LocalInvocationID.x);
    const Instance inst = instances[job / channels];
    channel = job % channels;
    const uint g = inst.ghost;
    const int grid = int(tableIndex[4u * g]);
    const int nA = int(tableIndex[4u * g + 2u]), crossings = int(tableIndex[4u * g + 3u]);
    const int dec = inst.decimation > 0 && grid % inst.decimation == 0 ? inst.decimation : 1;
    n = grid / dec;
    C = min(kMaxConstraints, nA + crossings * blades);
    S = 4 + C;
    J = 3 + C;
    base = uint(local) * uint(slot);
    flux = jobs[local].flux;
    flatness = inst.flatnessPx;
    edgeFlatness = inst.edgeFlatnessPx;
    tolerance = finite(inst.irradianceError) ? inst.irradianceError * jobs[local].brightest : 0.0LF;
    kEdge = clamp(int(ceil(max(jobs[local].xMax - jobs[local].xMin, jobs[local].yMax - jobs[local].yMin) / double(n) /
                           subcellPx)),
                  1, maxSubdivision);

    polys = verts = 0u;
    energySum = areaSum = 0.0;
    const int cells = jobs[local].lit != 0u ? n * n : 0;
    if (pass == 1) {
        // Each invocation writes from its offset up to the next one's (what pass 0 counted).
        const uint p0 = jobCounts[local], v0 = jobCounts[vertsAt + local];
        polyCursor = p0 + jobs[local].chunkPolys[lid];
        vertCursor = v0 + jobs[local].chunkVerts[lid];
        polyEnd = lid + 1 < LOCAL_SIZE ? p0 + jobs[local].chunkPolys[lid + 1] : jobCounts[local + 1];
        vertEnd = lid + 1 < LOCAL_SIZE ? v0 + jobs[local].chunkVerts[lid + 1] : jobCounts[vertsAt + local + 1];
    }
    for (int c = lid; c < cells; c += LOCAL_SIZE) cell(c % n, c / n);

    if (pass == 0) {
        // The invocations' exclusive scan (Hillis-Steele in shared memory).
        sPolys[lid] = polys;
        sVerts[lid] = verts;
        memoryBarrierShared();
        barrier();
        for (int step = 1; step < LOCAL_SIZE; step *= 2) {
            const uint p = lid >= step ? sPolys[lid - step] : 0u, v = lid >= step ? sVerts[lid - step] : 0u;
            memoryBarrierShared();
            barrier();
            sPolys[lid] += p;
            sVerts[lid] += v;
            memoryBarrierShared();
            barrier();
        }
        jobs[local].chunkPolys[lid] = sPolys[lid] - polys;
        jobs[local].chunkVerts[lid] = sVerts[lid] - verts;
        if (lid == LOCAL_SIZE - 1) {
            jobCounts[local] = sPolys[lid];
            jobCounts[vertsAt + local] = sVerts[lid];
        }
        return;
    }
    // Pass 1: the job's energy and area, summed in a fixed order.
    sEnergy[lid] = energySum;
    sArea[lid] = areaSum;
    memoryBarrierShared();
    barrier();
    for (int step = LOCAL_SIZE / 2; step > 0; step /= 2) {
        if (lid < step) {
            sEnergy[lid] += sEnergy[lid + step];
            sArea[lid] += sArea[lid + step];
        }
        memoryBarrierShared();
        barrier();
    }
    if (lid == 0) jobStats[local] = dvec2(sEnergy[0], sArea[0]);
}
