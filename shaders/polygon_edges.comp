#version 450
// The shaped ghosts' polygons (ghosts/shaped_ghosts.h) with exact pixel-area coverage: the GPU port of
// trace::CoverageRaster (trace/flare_raster.cpp), one invocation per polygon, in double precision as
// on the CPU. A polygon of uniform density d = e / area adds, for each edge and each row the edge
// crosses, d x (the area right of the edge within each column) to that column's entry; the row's
// prefix sum (polygon_rows.comp) turns the entries into density x covered area. A linear density
// adds the exact integrals in the columns an edge spans and its slope beyond, summed twice. A polygon inside one
// pixel puts e in it; one of no area is splatted bilinearly at its vertices' mean.
//
// The entries are 64-bit fixed point (two 32-bit words, two's complement, `scale` units per unit of
// energy), added with 32-bit atomics: integer sums do not depend on the order of the additions, so
// the image has the same bytes however the invocations run. Sums are exact modulo 2^64, so an edge's
// large entries (a sliver's density) cancel with its partner's as long as every final prefix sum
// fits 63 bits: the host sets scale from a bound on the frame's energy.

layout(local_size_x = LOCAL_SIZE) in;

const int kMaxPolygon = 43; // ghosts/shaped_ghosts.cpp: kMaxConstraints + 3 vertices

struct Polygon {
    uint first;   // index of its first vertex
    uint count;   // vertices, in order
    uint channel;
    uint pad;
    double energy;
    double gx, gy; // the density's gradient relative to its mean, per pixel (0: uniform)
};

layout(std430, binding = 0) readonly buffer Vertices { vec2 vertices[]; }; // pixels, origin top-left
layout(std430, binding = 1) readonly buffer Polygons { Polygon polygons[]; };
// [part][channel][row][width + 2] x {low, high}: part 0 the entries, part 1 the slopes of linear
// densities (CoverageRaster's acc_ and slope_).
layout(std430, binding = 2) buffer Accumulator { uint acc[]; };

uniform int width;
uniform int height;
uniform int count;
uniform int channels;
uniform double scale; // fixed-point units per unit of energy

const double kWord = 4294967296.0LF;

// Adds v (energy) to entry (x, y) of channel c of part `part`: v x scale rounded, modulo 2^64.
void addEntryTo(uint part, uint c, int y, int x, double v) {
    double q = roundEven(v * scale);
    const bool negative = q < 0.0;
    q = abs(q);
    const double high = floor(q / kWord);
    uint lo = uint(q - high * kWord);
    uint hi = uint(high - floor(high / kWord) * kWord);
    if (negative) {
        lo = ~lo + 1u;
        hi = ~hi + (lo == 0u ? 1u : 0u);
    }
    if (lo == 0u && hi == 0u) return;
    const uint i = 2u * (((part * uint(channels) + c) * uint(height) + uint(y)) * uint(width + 2) + uint(x));
    const uint old = atomicAdd(acc[i], lo);
    const uint carry = old + lo < old ? 1u : 0u; // the low word wrapped
    if (hi + carry != 0u) atomicAdd(acc[i + 1u], hi + carry);
}

void addEntry(uint c, int y, int x, double v) {
    addEntryTo(0u, c, y, x, v);
}

void pixel(uint c, int px, int py, double e) {
    if (px < 0 || py < 0 || px >= width || py >= height) return;
    addEntry(c, py, px, e); // the prefix sum carries it to px only
    addEntry(c, py, px + 1, -e);
}

void splat(uint c, dvec2 p, double e) {
    const double fx = p.x - 0.5, fy = p.y - 0.5;
    const double ix = floor(fx), iy = floor(fy);
    if (!(abs(ix) < 1e9LF && abs(iy) < 1e9LF)) return;
    const double ax = fx - ix, ay = fy - iy;
    const int x = int(ix), y = int(iy);
    pixel(c, x, y, e * (1.0 - ax) * (1.0 - ay));
    pixel(c, x + 1, y, e * ax * (1.0 - ay));
    pixel(c, x, y + 1, e * (1.0 - ax) * ay);
    pixel(c, x + 1, y + 1, e * ax * ay);
}

// p0.y < p1.y, both inside [0, W] x [0, H]: in each row the segment crosses, the area right of it
// (times d) split over the columns it spans (CoverageRaster::segment).
void segment(uint c, dvec2 p0, dvec2 p1, double d) {
    const double dxdy = (p1.x - p0.x) / (p1.y - p0.y);
    double x = p0.x;
    const int rowFrom = int(floor(p0.y)), rowTo = min(int(ceil(p1.y)), height);
    for (int y = rowFrom; y < rowTo; ++y) {
        const double dy = min(double(y) + 1.0, p1.y) - max(double(y), p0.y);
        const double xNext = double(y) + 1.0 >= p1.y ? p1.x : x + dxdy * dy;
        const double h = dy * d;
        const double x0 = min(x, xNext), x1 = max(x, xNext);
        const double x0Floor = floor(x0), x1Ceil = ceil(x1);
        const int i0 = int(x0Floor), i1 = int(x1Ceil);
        if (i1 <= i0 + 1) {
            const double f = 0.5 * (x + xNext) - x0Floor;
            addEntry(c, y, i0, h * (1.0 - f));
            addEntry(c, y, i0 + 1, h * f);
        } else {
            const double s = 1.0 / (x1 - x0);
            const double f0 = x0 - x0Floor;
            const double a0 = 0.5 * s * (1.0 - f0) * (1.0 - f0);
            const double f1 = x1 - x1Ceil + 1.0;
            const double am = 0.5 * s * f1 * f1;
            addEntry(c, y, i0, h * a0);
            if (i1 == i0 + 2) {
                addEntry(c, y, i0 + 1, h * (1.0 - a0 - am));
            } else {
                const double a1 = s * (1.5 - f0);
                addEntry(c, y, i0 + 1, h * (a1 - a0));
                for (int i = i0 + 2; i < i1 - 1; ++i) addEntry(c, y, i, h * s);
                const double a2 = a1 + double(i1 - i0 - 3) * s;
                addEntry(c, y, i1 - 1, h * (1.0 - a2 - am));
            }
            addEntry(c, y, i1, h * am);
        }
        x = xNext;
    }
}

// The density d.x + d.y x + d.z y: in each row the segment crosses, each column it spans gets the
// exact integral right of it, and from column i1 on the columns get the value at i1 and the slope,
// which the row pass sums twice (CoverageRaster::linearSegment).
double columnIntegral(int j, double ya, double yb, double xa, double xb, dvec3 d) {
    const double left = double(j), right = double(j) + 1.0, h = yb - ya;
    double cuts[4] = double[4](ya, yb, yb, yb);
    int n = 1;
    if ((xa - left) * (xb - left) < 0.0) cuts[n++] = ya + h * (left - xa) / (xb - xa);
    if ((xa - right) * (xb - right) < 0.0) cuts[n++] = ya + h * (right - xa) / (xb - xa);
    if (n == 3 && cuts[1] > cuts[2]) {
        const double t = cuts[1];
        cuts[1] = cuts[2];
        cuts[2] = t;
    }
    cuts[n] = yb;
    double sum = 0.0;
    for (int k = 0; k < n; ++k) {
        const double a = cuts[k], b = cuts[k + 1];
        double g[3];
        for (int q = 0; q < 3; ++q) {
            const double yy = q == 0 ? a : q == 1 ? 0.5 * (a + b) : b;
            const double u = clamp(h > 0.0 ? xa + (xb - xa) * (yy - ya) / h : xa, left, right);
            g[q] = (d.x + d.z * yy) * (right - u) + 0.5 * d.y * (right * right - u * u);
        }
        sum += (b - a) / 6.0 * (g[0] + 4.0 * g[1] + g[2]);
    }
    return sum;
}

void linearSegment(uint c, dvec2 p0, dvec2 p1, dvec3 d) {
    const double dxdy = (p1.x - p0.x) / (p1.y - p0.y);
    double x = p0.x;
    const int rowFrom = int(floor(p0.y)), rowTo = min(int(ceil(p1.y)), height);
    for (int y = rowFrom; y < rowTo; ++y) {
        const double ya = max(double(y), p0.y), yb = min(double(y) + 1.0, p1.y);
        const double h = yb - ya;
        const double xNext = double(y) + 1.0 >= p1.y ? p1.x : x + dxdy * h;
        const int i0 = int(floor(min(x, xNext))), i1 = int(ceil(max(x, xNext)));
        double before = 0.0;
        for (int j = i0; j < i1; ++j) {
            const double v = columnIntegral(j, ya, yb, x, xNext, d);
            addEntry(c, y, j, v - before);
            before = v;
        }
        addEntry(c, y, i1, h * (d.x + d.z * 0.5 * (ya + yb) + d.y * (double(i1) + 0.5)) - before);
        addEntryTo(1u, c, y, i1, h * d.y);
        x = xNext;
    }
}

// One edge, clipped to the frame's rows; the part left of the frame moved onto x = 0, the part right
// of it dropped (CoverageRaster::edge).
void edge(uint c, dvec2 a, dvec2 b, dvec3 d) {
    if (a.y == b.y) return;
    if (a.y > b.y) {
        const dvec2 t = a;
        a = b;
        b = t;
        d = -d;
    }
    const bool linear = d.y != 0.0 || d.z != 0.0;
    const double H = double(height), W = double(width);
    const double y0 = max(a.y, 0.0), y1 = min(b.y, H);
    if (!(y0 < y1)) return;
    const double dxdy = (b.x - a.x) / (b.y - a.y);
    const dvec2 p = dvec2(a.x + (y0 - a.y) * dxdy, y0), q = dvec2(a.x + (y1 - a.y) * dxdy, y1);
    double tA = 2.0, tB = 2.0;
    if (p.x * q.x < 0.0) tA = -p.x / (q.x - p.x);
    if ((p.x - W) * (q.x - W) < 0.0) tB = (W - p.x) / (q.x - p.x);
    if (tB < tA) {
        const double t = tA;
        tA = tB;
        tB = t;
    }
    const double cuts[4] = double[4](0.0, min(tA, 1.0), min(tB, 1.0), 1.0);
    for (int k = 0; k < 3; ++k) {
        const double t0 = cuts[k], t1 = cuts[k + 1];
        if (!(t1 > t0)) continue;
        dvec2 s = p + t0 * (q - p), t = p + t1 * (q - p);
        const double xm = 0.5 * (s.x + t.x);
        if (xm >= W) continue;
        if (xm <= 0.0) s.x = t.x = 0.0;
        s.x = clamp(s.x, 0.0, W);
        t.x = clamp(t.x, 0.0, W);
        if (linear)
            linearSegment(c, s, t, d);
        else
            segment(c, s, t, d.x);
    }
}

void main() {
    const int k = int(gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x);
    if (k >= count) return;
    const Polygon g = polygons[k];
    const int n = min(int(g.count), kMaxPolygon);
    if (n == 0 || g.energy == 0.0) return;
    dvec2 poly[kMaxPolygon];
    dvec2 lo = dvec2(1e300LF), hi = dvec2(-1e300LF);
    double area = 0.0, mx = 0.0, my = 0.0;
    for (int i = 0; i < n; ++i) {
        poly[i] = dvec2(vertices[g.first + uint(i)]);
        lo = min(lo, poly[i]);
        hi = max(hi, poly[i]);
    }
    for (int i = 0; i < n; ++i) {
        const dvec2 p = poly[i], q = poly[(i + 1) % n];
        const double cross = p.x * q.y - q.x * p.y;
        area += cross;
        mx += (p.x + q.x) * cross;
        my += (p.y + q.y) * cross;
    }
    area *= 0.5;
    mx /= 6.0;
    my /= 6.0;
    // a vertex at infinity or NaN: nowhere in the image
    if (isnan(area) || isinf(area) || isnan(mx) || isinf(mx) || isnan(my) || isinf(my)) return;
    const bool nearFrame = abs(lo.x) < 1e9LF && abs(lo.y) < 1e9LF;
    if (nearFrame && floor(lo.x) == floor(hi.x) && floor(lo.y) == floor(hi.y) && area != 0.0) {
        pixel(g.channel, int(floor(lo.x)), int(floor(lo.y)), g.energy);
        return;
    }
    if (area == 0.0) {
        dvec2 mean = dvec2(0.0);
        for (int i = 0; i < n; ++i) mean += poly[i];
        splat(g.channel, mean / double(n), g.energy);
        return;
    }
    // The density (e / |A|) (1 + g . (p - c)), with the orientation's sign (CoverageRaster::polygon).
    const double s = -g.energy / area;
    const dvec2 c = dvec2(mx, my) / area;
    const dvec3 d = (g.gx != 0.0 || g.gy != 0.0)
                        ? s * dvec3(1.0 - g.gx * c.x - g.gy * c.y, g.gx, g.gy)
                        : dvec3(s, 0.0, 0.0);
    for (int i = 0; i < n; ++i) edge(g.channel, poly[i], poly[(i + 1) % n], d);
}
