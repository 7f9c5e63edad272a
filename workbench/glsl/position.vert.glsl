#version 330
// position path (and every path's wire-frame pass): positions only
#include "common.vert.glsl"
in vec3 position;

void main() {
    place(position);
}
