// The 1-D colormap texture (one row, clamp to edge; linear for smooth contours, nearest for
// bands) and the map from normalised value t to texture coordinate s = t * scale + offset.
uniform sampler2D colormap;
uniform vec2 colormap_st;

float colormap_coord(float t) {
    return t * colormap_st.x + colormap_st.y;
}

vec4 colormap_lookup(float s) {
    return textureLod(colormap, vec2(s, 0.5), 0.0);
}
