#version 450
// The binned polygon raster's drawing pass: one work group per bin (a channel's 16 x 16-pixel tile)
// draws the polygons of its list (polygon_bins.comp) with the exact pixel-area coverage of
// trace::CoverageRaster, in double, into the tile's entries in shared memory, then takes each row's
// prefix sum and adds it to the frame's accumulator once per pixel.
//
// Each edge is cut to the tile's rows; its part left of the tile moves onto the tile's left side and
// its part right of it is dropped (as CoverageRaster does with the frame), so a closed polygon adds
// density x covered area to every pixel of the tile, whatever lies outside it. In each row an edge
// crosses it adds d x (the area right of it within each column) to the columns it spans; a linear
// density adds the exact integrals in those columns, and the value and slope beyond, summed twice.
//
// Entries are 64-bit fixed point (two 32-bit words, two's complement, `scale` units per unit of
// energy) added with 32-bit shared-memory atomics; the accumulator sums the tiles' rows modulo 2^64.
// Integer sums do not depend on the order of the additions: the image has the same bytes on any run
// and for any batching; a sliver's large entries cancel exactly with its partner's.

layout(local_size_x = LOCAL_SIZE) in;

const int kTile = 16;
const int kMaxPolygon = 43; // ghosts/shaped_ghosts.cpp: kMaxConstraints + 3 vertices

struct Polygon {
    uint first;
    uint count;
    uint channel;
    uint splat;
    double energy;
    double gx, gy;
};

struct Prepared { // polygon_bins.comp
    double dx, dy, dz;
    double pad0, pad1;
    uint kind;
    int tx0, tx1, ty0, ty1;
    uint pad2;
};

layout(std430, binding = 0) readonly buffer Vertices { vec2 vertices[]; };
layout(std430, binding = 1) readonly buffer Polygons { Polygon polygons[]; };
// [channel][row][column] x {low, high}: the frame's sums, modulo 2^64 (polygon_image.comp reads them).
layout(std430, binding = 2) buffer Accumulator { uint acc[]; };
layout(std430, binding = 4) readonly buffer PreparedPolygons { Prepared prepared[]; };
layout(std430, binding = 6) readonly buffer Lists { uint lists[]; };
layout(std430, binding = 7) readonly buffer Offsets { uint offsets[]; };

uniform int width;
uniform int height;
uniform int tilesX;
uniform int tilesY;
uniform int bins;
uniform int firstPolygon; // the lists index polygons from here (polygon_bins.comp)
uniform double scale; // fixed-point units per unit of energy

const double kWord = 4294967296.0LF;

// [part][row][column] x {low, high}: part 0 the entries, part 1 the slopes of linear densities.
shared uint entries[2 * kTile * kTile * 2];

int X0, Y0; // the tile's top-left pixel

// Adds v (energy) to the tile's entry at frame pixel (x, y) of `part`: v x scale rounded, modulo
// 2^64. Columns right of the tile drop out (their prefix sums are other tiles').
void addEntryTo(int part, int y, int x, double v) {
    const int col = x - X0, row = y - Y0;
    if (col < 0 || col >= kTile || row < 0 || row >= kTile) return;
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
    const int i = 2 * ((part * kTile + row) * kTile + col);
    const uint old = atomicAdd(entries[i], lo);
    const uint carry = old + lo < old ? 1u : 0u; // the low word wrapped
    if (hi + carry != 0u) atomicAdd(entries[i + 1], hi + carry);
}

void addEntry(int y, int x, double v) {
    addEntryTo(0, y, x, v);
}

// e in pixel (px, py) of this tile (other tiles' pixels are theirs).
void pixel(int px, int py, double e) {
    if (px < X0 || px >= min(X0 + kTile, width) || py >= height) return;
    addEntry(py, px, e); // the prefix sum carries it to px only
    addEntry(py, px + 1, -e);
}

void splat(dvec2 p, double e) {
    const double fx = p.x - 0.5, fy = p.y - 0.5;
    const double ix = floor(fx), iy = floor(fy);
    const double ax = fx - ix, ay = fy - iy;
    const int x = int(ix), y = int(iy);
    pixel(x, y, e * (1.0 - ax) * (1.0 - ay));
    pixel(x + 1, y, e * ax * (1.0 - ay));
    pixel(x, y + 1, e * (1.0 - ax) * ay);
    pixel(x + 1, y + 1, e * ax * ay);
}

// p0.y < p1.y, both inside the tile: in each row the segment crosses, the area right of it (times d)
// split over the columns it spans (CoverageRaster::segment).
void segment(dvec2 p0, dvec2 p1, double d) {
    const double dxdy = (p1.x - p0.x) / (p1.y - p0.y);
    double x = p0.x;
    const int rowFrom = int(floor(p0.y)), rowTo = min(int(ceil(p1.y)), Y0 + kTile);
    for (int y = rowFrom; y < rowTo; ++y) {
        const double dy = min(double(y) + 1.0, p1.y) - max(double(y), p0.y);
        const double xNext = double(y) + 1.0 >= p1.y ? p1.x : x + dxdy * dy;
        const double h = dy * d;
        const double x0 = min(x, xNext), x1 = max(x, xNext);
        const double x0Floor = floor(x0), x1Ceil = ceil(x1);
        const int i0 = int(x0Floor), i1 = int(x1Ceil);
        if (i1 <= i0 + 1) {
            const double f = 0.5 * (x + xNext) - x0Floor;
            addEntry(y, i0, h * (1.0 - f));
            addEntry(y, i0 + 1, h * f);
        } else {
            const double s = 1.0 / (x1 - x0);
            const double f0 = x0 - x0Floor;
            const double a0 = 0.5 * s * (1.0 - f0) * (1.0 - f0);
            const double f1 = x1 - x1Ceil + 1.0;
            const double am = 0.5 * s * f1 * f1;
            addEntry(y, i0, h * a0);
            if (i1 == i0 + 2) {
                addEntry(y, i0 + 1, h * (1.0 - a0 - am));
            } else {
                const double a1 = s * (1.5 - f0);
                addEntry(y, i0 + 1, h * (a1 - a0));
                for (int i = i0 + 2; i < i1 - 1; ++i) addEntry(y, i, h * s);
                const double a2 = a1 + double(i1 - i0 - 3) * s;
                addEntry(y, i1 - 1, h * (1.0 - a2 - am));
            }
            addEntry(y, i1, h * am);
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

void linearSegment(dvec2 p0, dvec2 p1, dvec3 d) {
    const double dxdy = (p1.x - p0.x) / (p1.y - p0.y);
    double x = p0.x;
    const int rowFrom = int(floor(p0.y)), rowTo = min(int(ceil(p1.y)), Y0 + kTile);
    for (int y = rowFrom; y < rowTo; ++y) {
        const double ya = max(double(y), p0.y), yb = min(double(y) + 1.0, p1.y);
        const double h = yb - ya;
        const double xNext = double(y) + 1.0 >= p1.y ? p1.x : x + dxdy * h;
        const int i0 = int(floor(min(x, xNext))), i1 = int(ceil(max(x, xNext)));
        double before = 0.0;
        for (int j = i0; j < i1; ++j) {
            const double v = columnIntegral(j, ya, yb, x, xNext, d);
            addEntry(y, j, v - before);
            before = v;
        }
        addEntry(y, i1, h * (d.x + d.z * 0.5 * (ya + yb) + d.y * (double(i1) + 0.5)) - before);
        addEntryTo(1, y, i1, h * d.y);
        x = xNext;
    }
}

// One edge, cut to the tile's rows; the part left of the tile moved onto its left side, the part
// right of it dropped (CoverageRaster::edge, with the tile for the frame).
void edge(dvec2 a, dvec2 b, dvec3 d) {
    if (a.y == b.y) return;
    if (a.y > b.y) {
        const dvec2 t = a;
        a = b;
        b = t;
        d = -d;
    }
    const bool linear = d.y != 0.0 || d.z != 0.0;
    const double left = double(X0), right = double(X0 + kTile);
    const double y0 = max(a.y, double(Y0)), y1 = min(b.y, double(Y0 + kTile));
    if (!(y0 < y1)) return;
    const double dxdy = (b.x - a.x) / (b.y - a.y);
    const dvec2 p = dvec2(a.x + (y0 - a.y) * dxdy, y0), q = dvec2(a.x + (y1 - a.y) * dxdy, y1);
    if (p.x >= right && q.x >= right) return;
    double tA = 2.0, tB = 2.0;
    if ((p.x - left) * (q.x - left) < 0.0) tA = (left - p.x) / (q.x - p.x);
    if ((p.x - right) * (q.x - right) < 0.0) tB = (right - p.x) / (q.x - p.x);
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
        if (xm >= right) continue;
        if (xm <= left) s.x = t.x = left;
        s.x = clamp(s.x, left, right);
        t.x = clamp(t.x, left, right);
        if (linear)
            linearSegment(s, t, d);
        else
            segment(s, t, d.x);
    }
}

void drawPolygon(uint k) {
    const Prepared p = prepared[k];
    if (p.kind == 1u) {
        pixel(int(p.dy), int(p.dz), p.dx);
    } else if (p.kind == 2u) {
        splat(dvec2(p.dy, p.dz), p.dx);
    } else if (p.kind == 3u) {
        const Polygon g = polygons[uint(firstPolygon) + k];
        const int n = min(int(g.count), kMaxPolygon);
        const dvec3 d = dvec3(p.dx, p.dy, p.dz);
        dvec2 first = dvec2(vertices[g.first]), a = first;
        for (int i = 1; i <= n; ++i) {
            const dvec2 b = i < n ? dvec2(vertices[g.first + uint(i)]) : first;
            edge(a, b, d);
            a = b;
        }
    }
}

uvec2 add64(uvec2 a, uvec2 b) {
    const uint lo = a.x + b.x;
    return uvec2(lo, a.y + b.y + (lo < a.x ? 1u : 0u));
}

void main() {
    const uint bin = gl_WorkGroupID.x + gl_WorkGroupID.y * gl_NumWorkGroups.x;
    if (bin >= uint(bins)) return;
    const uint from = offsets[bin], to = offsets[bin + 1u];
    if (from == to) return; // the whole work group leaves together
    const uint tiles = uint(tilesX * tilesY), t = bin % tiles, channel = bin / tiles;
    X0 = int(t % uint(tilesX)) * kTile;
    Y0 = int(t / uint(tilesX)) * kTile;
    const uint lid = gl_LocalInvocationID.x;
    for (uint i = lid; i < uint(2 * kTile * kTile * 2); i += gl_WorkGroupSize.x) entries[i] = 0u;
    memoryBarrierShared();
    barrier();
    for (uint j = from + lid; j < to; j += gl_WorkGroupSize.x) drawPolygon(lists[j]);
    memoryBarrierShared();
    barrier();
    // Each row's prefix sum: the entries' running sum plus the ramp (the slopes' sum summed again).
    for (int row = int(lid); row < kTile && Y0 + row < height; row += int(gl_WorkGroupSize.x)) {
        const int y = Y0 + row;
        uvec2 sum = uvec2(0u), slope = uvec2(0u), ramp = uvec2(0u);
        for (int col = 0; col < kTile && X0 + col < width; ++col) {
            const int i = 2 * (row * kTile + col), s = i + 2 * kTile * kTile;
            sum = add64(sum, uvec2(entries[i], entries[i + 1]));
            ramp = add64(ramp, slope);
            slope = add64(slope, uvec2(entries[s], entries[s + 1]));
            const uint a = 2u * ((channel * uint(height) + uint(y)) * uint(width) + uint(X0 + col));
            const uvec2 total = add64(uvec2(acc[a], acc[a + 1u]), add64(sum, ramp));
            acc[a] = total.x;
            acc[a + 1u] = total.y;
        }
    }
}
