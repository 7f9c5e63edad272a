#version 330
// exploded path: one half of the split assembly (or the object of interest), translated.
// The split plane is relative to the upload origin and cuts the untranslated geometry; the
// half keeps split_side * (n.p + d) >= 0 (split_side 0: no cut, the object of interest).
// Clip distances 0..NUM_CLIP-1 are the style's planes (on the drawn, translated position),
// NUM_CLIP is the split plane.
#include "headlight.glsl"
uniform mat4 mvp;
uniform mat4 view;
uniform vec3 translate;
uniform vec4 split_plane;
uniform float split_side;
#if NUM_CLIP > 0
uniform vec4 clip_planes[NUM_CLIP];
#endif
out float gl_ClipDistance[NUM_CLIP + 1];
in vec3 position;
out vec3 eye_position;

void main() {
    vec3 p = position + translate;
    gl_Position = mvp * vec4(p, 1.0);
#if NUM_CLIP > 0
    for (int i = 0; i < NUM_CLIP; ++i) {
        gl_ClipDistance[i] = dot(clip_planes[i].xyz, p) + clip_planes[i].w;
    }
#endif
    gl_ClipDistance[NUM_CLIP] = split_side * (dot(split_plane.xyz, position) + split_plane.w);
    eye_position = (view * vec4(p, 1.0)).xyz;
}
