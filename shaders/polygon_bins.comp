#version 450
// First and third passes of the binned polygon raster (polygon_tiles.comp draws): per polygon of the
// batch, its kind, its density and the 16 x 16-pixel tiles it may touch (`prepared`), then, per bin (a
// channel's tile), pass 0 counts the polygons (atomically; bin_scan.comp turns the counts into
// offsets) and pass 1 writes each polygon's index into the lists of its bins (`counts` then holds the
// bins' cursors, starting at their offsets). The order within a list depends on the run; the tiles'
// integer sums do not.
//
// Kinds follow trace::CoverageRaster::polygon: 0 draws nothing (no vertex, no energy, a vertex at
// infinity or NaN, or off the frame), 1 fills one pixel (a polygon of area inside it), 2 splats its
// energy bilinearly at its vertices' mean (no area, or marked to be splatted), 3 adds its edges with the density
// d.x + d.y x + d.z y (pixels; uniform when d.y = d.z = 0), the orientation's sign included.

layout(local_size_x = LOCAL_SIZE) in;

const int kTile = 16;
const int kMaxPolygon = 43; // ghosts/shaped_ghosts.cpp: kMaxConstraints + 3 vertices

struct Polygon {
    uint first;   // index of its first vertex
    uint count;   // vertices, in order
    uint channel;
    uint splat;   // 1: splatted bilinearly at its vertices' mean whatever its area (kind 2)
    double energy;
    double gx, gy; // the density's gradient relative to its mean, per pixel (0: uniform)
};

struct Prepared {
    double dx, dy, dz; // kind 3: the density; kind 1: (energy, pixel x, pixel y); kind 2: (energy, mean)
    double pad0, pad1;
    uint kind;
    int tx0, tx1, ty0, ty1; // the tiles it may touch, inclusive (none when tx0 > tx1)
    uint pad2;
};

layout(std430, binding = 0) readonly buffer Vertices { vec2 vertices[]; }; // pixels, origin top-left
layout(std430, binding = 1) readonly buffer Polygons { Polygon polygons[]; };
layout(std430, binding = 4) buffer PreparedPolygons { Prepared prepared[]; };
layout(std430, binding = 5) buffer Counts { uint counts[]; }; // [channel][tile row][tile column]
layout(std430, binding = 6) writeonly buffer Lists { uint lists[]; };

uniform int width;
uniform int height;
uniform int count;
uniform int firstPolygon; // the batch is polygons[firstPolygon .. firstPolygon + count)
uniform int tilesX;
uniform int tilesY;
uniform int listPass; // 0: prepare and count, 1: write the lists

// The tiles of pixels lo .. hi (inclusive, clamped to the frame); none when the range is empty.
void tileRange(inout Prepared p, dvec2 lo, dvec2 hi) {
    const dvec2 a = max(lo, dvec2(0.0)), b = min(hi, dvec2(double(width - 1), double(height - 1)));
    if (!(a.x <= b.x && a.y <= b.y)) return;
    p.tx0 = int(a.x) / kTile;
    p.tx1 = int(b.x) / kTile;
    p.ty0 = int(a.y) / kTile;
    p.ty1 = int(b.y) / kTile;
}

Prepared prepare(Polygon g) {
    Prepared p;
    p.dx = p.dy = p.dz = p.pad0 = p.pad1 = 0.0;
    p.kind = 0u;
    p.tx0 = p.ty0 = 1;
    p.tx1 = p.ty1 = 0;
    p.pad2 = 0u;
    const int n = min(int(g.count), kMaxPolygon);
    if (n == 0 || g.energy == 0.0) return p;
    dvec2 lo = dvec2(1e300LF), hi = dvec2(-1e300LF), mean = dvec2(0.0);
    double area = 0.0, mx = 0.0, my = 0.0;
    for (int i = 0; i < n; ++i) {
        const dvec2 v = dvec2(vertices[g.first + uint(i)]), w = dvec2(vertices[g.first + uint((i + 1) % n)]);
        lo = min(lo, v);
        hi = max(hi, v);
        mean += v;
        const double cross = v.x * w.y - w.x * v.y;
        area += cross;
        mx += (v.x + w.x) * cross;
        my += (v.y + w.y) * cross;
    }
    area *= 0.5;
    mx /= 6.0;
    my /= 6.0;
    // a vertex at infinity or NaN: nowhere in the image
    if (isnan(area) || isinf(area) || isnan(mx) || isinf(mx) || isnan(my) || isinf(my)) return p;
    const bool nearFrame = abs(lo.x) < 1e9LF && abs(lo.y) < 1e9LF;
    if (g.splat == 0u && nearFrame && floor(lo.x) == floor(hi.x) && floor(lo.y) == floor(hi.y) && area != 0.0) {
        p.kind = 1u;
        p.dx = g.energy;
        p.dy = floor(lo.x);
        p.dz = floor(lo.y);
        tileRange(p, dvec2(p.dy, p.dz), dvec2(p.dy, p.dz));
        return p;
    }
    if (area == 0.0 || g.splat != 0u) {
        mean /= double(n);
        const dvec2 f = floor(mean - 0.5);
        if (!(abs(f.x) < 1e9LF && abs(f.y) < 1e9LF)) return p;
        p.kind = 2u;
        p.dx = g.energy;
        p.dy = mean.x;
        p.dz = mean.y;
        tileRange(p, f, f + 1.0);
        return p;
    }
    // The density (e / |A|) (1 + g . (p - c)), with the orientation's sign (CoverageRaster::polygon).
    const double s = -g.energy / area;
    const dvec2 c = dvec2(mx, my) / area;
    p.kind = 3u;
    if (g.gx != 0.0 || g.gy != 0.0) {
        p.dx = s * (1.0 - g.gx * c.x - g.gy * c.y);
        p.dy = s * g.gx;
        p.dz = s * g.gy;
    } else {
        p.dx = s;
    }
    // The pixels its edges cross; the part left of the frame lands on column 0 (polygon_tiles.comp).
    tileRange(p, floor(lo), ceil(hi) - 1.0);
    return p;
}

void main() {
    const int k = int(gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * gl_NumWorkGroups.x * gl_WorkGroupSize.x);
    if (k >= count) return;
    Prepared p;
    if (listPass == 0) {
        p = prepare(polygons[firstPolygon + k]);
        prepared[k] = p;
    } else {
        p = prepared[k];
    }
    const uint channel = polygons[firstPolygon + k].channel;
    for (int ty = p.ty0; ty <= p.ty1; ++ty)
        for (int tx = p.tx0; tx <= p.tx1; ++tx) {
            const uint bin = (channel * uint(tilesY) + uint(ty)) * uint(tilesX) + uint(tx);
            if (listPass == 0)
                atomicAdd(counts[bin], 1u);
            else
                lists[atomicAdd(counts[bin], 1u)] = uint(k);
        }
}
