#version 330
// fe2003 texture paths: per-pixel headlight from the two-component normal map (NORMAL_MAP 1)
// or the interpolated per-vertex light (NORMAL_MAP 0), and element outlines from the
// wire-frame distance texture (WIRE_TEXTURE 1) or from element ids and corners (WIRE_CORNERS
// 1); see workbench/algo/fepatch/surface.py and wireid.py.
#include "headlight.glsl"
uniform vec3 base_color;
in vec2 st;
out vec4 frag_color;
#if NORMAL_MAP
uniform mat4 view;
uniform sampler2D normal_map;
in vec3 eye_position;
flat in int normal_axis;
#else
in float light;
#endif
#if WIRE_CORNERS
uniform usampler2D element_map;   // element index within the subpatch, no_element for none
uniform usampler2D corner_table;  // one RGBA32UI texel per element: corners times corner_frac,
                                  // u in the low and v in the high 16 bits
uniform uint no_element;
uniform float corner_step;  // 1 / corner_frac
uniform vec3 wire_color;
flat in int element_base;
const float TIE = 1.0 / 1024.0;  // pixels

// squared distance from p to segment ab; keeps the smallest in best2 with its segment in edge
void segment(vec2 p, vec2 a, vec2 b, inout float best2, inout vec2 edge) {
    vec2 ab = b - a;
    vec2 ap = p - a;
    float len2 = dot(ab, ab);
    float t = clamp(dot(ap, ab) / max(len2, 1e-30), 0.0, 1.0);
    vec2 q = ap - t * ab;
    float d2 = dot(q, q);
    if (d2 < best2) { best2 = d2; edge = ab; }
}

// the edges of element row e of the corner table
void element_edges(vec2 p, int e, inout float best2, inout vec2 edge) {
    uvec4 q = texelFetch(corner_table, ivec2(e & (CORNER_ROW - 1), e >> CORNER_SHIFT), 0);
    vec2 a = vec2(uvec2(q.x & 0xFFFFu, q.x >> 16u)) * corner_step;
    vec2 b = vec2(uvec2(q.y & 0xFFFFu, q.y >> 16u)) * corner_step;
    vec2 c = vec2(uvec2(q.z & 0xFFFFu, q.z >> 16u)) * corner_step;
    vec2 d = vec2(uvec2(q.w & 0xFFFFu, q.w >> 16u)) * corner_step;
    segment(p, a, b, best2, edge);
    segment(p, b, c, best2, edge);
    segment(p, c, d, best2, edge);
    segment(p, d, a, best2, edge);
}
#endif
#if WIRE_TEXTURE
uniform sampler2D wire_map;
uniform float wire_range;  // texels of byte 0 / 255
uniform vec3 wire_color;

// one channel pair: on the outline where one distance is within half a pixel of zero while the
// other is not below minus half a pixel (w: the distance's change per pixel along the minor
// axis of its iso-line, like an aliased one-pixel GL line)
bool on_outline(float c1, float c2, float w1, float w2) {
    return (abs(c1) <= 0.5 * w1 && c2 >= -0.5 * w2) || (abs(c2) <= 0.5 * w2 && c1 >= -0.5 * w1);
}
#endif

void main() {
#if WIRE_CORNERS
    // the atlas position in texels and its change per pixel, in uniform control flow
    ivec2 size = textureSize(element_map, 0);
    vec2 t = st * vec2(size);
    vec2 tx = dFdx(t), ty = dFdy(t);
    ivec2 i0 = ivec2(floor(t - 0.5));
    ivec2 hi = size - 1;
    uint id0 = texelFetch(element_map, clamp(i0, ivec2(0), hi), 0).r;
    uint id1 = texelFetch(element_map, clamp(i0 + ivec2(1, 0), ivec2(0), hi), 0).r;
    uint id2 = texelFetch(element_map, clamp(i0 + ivec2(0, 1), ivec2(0), hi), 0).r;
    uint id3 = texelFetch(element_map, clamp(i0 + ivec2(1, 1), ivec2(0), hi), 0).r;
    float best2 = 1e30;
    vec2 edge = vec2(0.0, 1.0);
    // each distinct element once
    if (id0 != no_element) element_edges(t, element_base + int(id0), best2, edge);
    if (id1 != no_element && id1 != id0) element_edges(t, element_base + int(id1), best2, edge);
    if (id2 != no_element && id2 != id0 && id2 != id1)
        element_edges(t, element_base + int(id2), best2, edge);
    if (id3 != no_element && id3 != id0 && id3 != id1 && id3 != id2)
        element_edges(t, element_base + int(id3), best2, edge);
    float best = sqrt(best2);
    vec2 best_n = normalize(vec2(-edge.y, edge.x) + vec2(1e-30, 0.0));
    // on the outline within half a pixel, a pixel measured along the minor axis of the edge
    // (the distance's change per pixel, like an aliased one-pixel GL line); a line on a pixel
    // border, a tie up to rounding, draws both pixels rather than neither
    bool wire = best <= (0.5 + TIE) * max(abs(dot(best_n, tx)), abs(dot(best_n, ty)));
#endif
#if WIRE_TEXTURE
    // signed distances in texels; derivatives taken here, in uniform control flow
    vec4 c = (texture(wire_map, st) * 255.0 - 127.5) / 127.5 * wire_range;
    vec4 w = max(abs(dFdx(c)), abs(dFdy(c)));
    bool wire = on_outline(c.g, c.b, w.g, w.b) || on_outline(c.r, c.a, w.r, w.a);
#endif
#if NORMAL_MAP
    vec2 kept = texture(normal_map, st).rg * 2.0 - 1.0;  // q / 127.5 - 1
    float restored = sqrt(max(0.0, 1.0 - dot(kept, kept)));
    vec3 n = normal_axis == 0 ? vec3(restored, kept.x, kept.y)
           : normal_axis == 1 ? vec3(kept.x, restored, kept.y)
                              : vec3(kept.x, kept.y, restored);
    float light = headlight(mat3(view) * n, eye_position);
#endif
    vec3 color = base_color * light;
#if WIRE_TEXTURE || WIRE_CORNERS
    if (wire) {
        color = wire_color;
    }
#endif
    frag_color = vec4(color, 1.0);
}
