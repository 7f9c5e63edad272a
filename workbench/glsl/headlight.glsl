// Two-sided headlight without specular: 0.25 + 0.75 |n.l|, l towards the viewer in eye space
// ((0, 0, 1) orthographic, -p/|p| perspective). n need not be unit; a zero n gets 0.25.
uniform float perspective;

float headlight(vec3 n, vec3 eye_position) {
    vec3 l = perspective > 0.5 ? normalize(-eye_position) : vec3(0.0, 0.0, 1.0);
    float len2 = dot(n, n);
    return 0.25 + 0.75 * (len2 > 0.0 ? abs(dot(n, l)) * inversesqrt(len2) : 0.0);
}
