#version 330
// beams and SPH particles: the paint of kinds.vert.glsl; a particle is a disc of its point
// size, shaded as a sphere seen along the view (0.25 + 0.75 n_z), depth of its centre
#include "colormap.glsl"
flat in vec4 v_paint;
flat in float v_value;
out vec4 frag_color;

void main() {
    vec3 c = v_paint.rgb;
    if (v_paint.a > 1.5) {
        c = missing_color;
    } else if (v_paint.a > 0.5) {
        c = colormap_lookup(colormap_coord(v_value)).rgb;
    }
    float light = 1.0;
#ifdef POINTS
    vec2 q = gl_PointCoord * 2.0 - 1.0;
    float rr = dot(q, q);
    if (rr > 1.0) discard;
    light = 0.25 + 0.75 * sqrt(1.0 - rr);
#endif
    frag_color = vec4(c * light, 1.0);
}
