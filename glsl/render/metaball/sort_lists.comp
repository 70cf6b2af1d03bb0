#version 450
// Sorted S-buffer (an extension of seed 000): each pixel's contiguous range is heap-sorted
// in place by the view depth of its metaballs' centres (depths.comp), so a sample at depth z needs only
// the window of centres within z +- R (found by binary search in march.comp). Heap sort:
// O(n log n) loop iterations whatever the order, within llvmpipe's loop budget for lists
// of thousands; a loop that does not end by its own condition counts the pixel as cut.
#include "common/index.glsl"
#include "common.glsl"

float key(uint s) { return depths[list[s]]; }

bool cut = false;

// Sift the entry at heap index i down a heap of n entries starting at slot base.
void sift(uint base, uint i, uint n) {
    uint v = list[base + i];
    float kv = depths[v];
    uint c = 2u * i + 1u;
    bool done = false;
    while (!done && c < n) {
        float kc = key(base + c);
        if (c + 1u < n) {
            float kr = key(base + c + 1u);
            if (kr > kc) { c++; kc = kr; }
        }
        if (kc <= kv) {
            done = true;
        } else {
            list[base + i] = list[base + c];
            i = c;
            c = 2u * i + 1u;
        }
    }
    if (!done && c < n) cut = true;
    list[base + i] = v;
}

void main() {
    uint p = global_id();
    if (p >= P.width * P.height) return;
    uint base = range_start(p), end = min(offsets[p], P.list_capacity);
    if (end <= base + 1u) return;
    uint n = end - base;
    uint i = n / 2u;
    for (; i > 0u; --i) sift(base, i - 1u, n);
    if (i > 0u) cut = true;
    uint m = n;
    for (; m > 1u; --m) {
        uint top = list[base];
        list[base] = list[base + m - 1u];
        list[base + m - 1u] = top;
        sift(base, 0u, m - 1u);
    }
    if (m > 1u) cut = true;
    if (cut) atomicAdd(stats.budget_pixels, 1u);
}
