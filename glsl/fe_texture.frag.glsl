#version 330
// fe2003 texture paths: per-pixel headlight from the two-component normal map (NORMAL_MAP 1)
// or the interpolated per-vertex light (NORMAL_MAP 0), and element outlines from the
// wire-frame distance texture (WIRE_TEXTURE 1); see workbench/algo/fepatch/surface.py.
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
#if WIRE_TEXTURE
    if (wire) {
        color = wire_color;
    }
#endif
    frag_color = vec4(color, 1.0);
}
