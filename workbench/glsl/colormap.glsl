// The 1-D colormap texture (one row, clamp to edge; linear for smooth contours, nearest for
// bands) and the map from normalised value t to texture coordinate s = t * scale + offset.
// A non-finite field value arrives as the sentinel -1e30 (workbench.paths.colormap.NO_VALUE) and
// is drawn in missing_color, opaque, whatever the transfer function says.
uniform sampler2D colormap;
uniform vec2 colormap_st;
uniform vec3 missing_color;

float colormap_coord(float t) {
    return t * colormap_st.x + colormap_st.y;
}

vec4 colormap_lookup(float s) {
    return textureLod(colormap, vec2(s, 0.5), 0.0);
}

vec4 colormap_color(float s) {
    return s < -1.0e29 ? vec4(missing_color, 1.0) : colormap_lookup(s);
}
