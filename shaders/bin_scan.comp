#version 450
// The exclusive prefix sum of n counts in one work group: offsets[i] = counts[0] + ... + counts[i - 1],
// offsets[n] the total (the binned polygon raster's list offsets, polygon_bins.comp). Each invocation
// sums a contiguous chunk, the chunks' sums are scanned in shared memory, each chunk is written.

layout(local_size_x = LOCAL_SIZE) in;

layout(std430, binding = 5) readonly buffer Counts { uint counts[]; };
layout(std430, binding = 7) writeonly buffer Offsets { uint offsets[]; };

uniform int n;

shared uint partial[LOCAL_SIZE];

void main() {
    const uint lid = gl_LocalInvocationID.x;
    const uint chunk = (uint(n) + LOCAL_SIZE - 1u) / LOCAL_SIZE;
    const uint from = min(lid * chunk, uint(n)), to = min(from + chunk, uint(n));
    uint sum = 0u;
    for (uint i = from; i < to; ++i) sum += counts[i];
    partial[lid] = sum;
    memoryBarrierShared();
    barrier();
    // Hillis-Steele inclusive scan of the chunks' sums.
    for (uint step = 1u; step < LOCAL_SIZE; step *= 2u) {
        const uint v = lid >= step ? partial[lid - step] : 0u;
        memoryBarrierShared();
        barrier();
        partial[lid] += v;
        memoryBarrierShared();
        barrier();
    }
    uint running = partial[lid] - sum;
    for (uint i = from; i < to; ++i) {
        offsets[i] = running;
        running += counts[i];
    }
    if (lid == LOCAL_SIZE - 1u) offsets[n] = partial[lid];
}
