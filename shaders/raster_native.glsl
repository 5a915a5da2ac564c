// The native raster of the geometry passes (--gl-raster native, the default; prepended before
// raster_common.glsl with raster_native.vert): GL's own clipper, rasterizer (its fill rule and
// sub-pixel precision) and perspective-correct interpolation, in single precision, no geometry
// shader. This is the part an engine replaces with its own vertex outputs: a fragment is the
// pixel GL shades, its depth gl_FragCoord.z, its normal, uv and colour the interpolated varyings, its
// material the triangle's (gl_PrimitiveID indexes the draw's triangles).
in vec3 vNormal;  // view space
in vec2 vUv;
in vec4 vColor;  // perspective-correct vertex colour

uniform ivec2 uSize;
uniform uint uVertexColors;  // the scene has vertex colours (else vColor is white, not multiplied)

layout(std430, binding = kBindTriMaterial) readonly buffer TriMaterial {
  uint triMaterial[];
};

struct FragmentData {
  ivec2 px;   // pixel, rows top to bottom (raster_native.vert flips y)
  int pixel;  // px.y * width + px.x
};

// every fragment GL generates is covered
bool rasterFragment(out FragmentData f) {
  f.px = ivec2(gl_FragCoord.xy);
  f.pixel = f.px.y * uSize.x + f.px.x;
  return true;
}

uint fragmentMaterial() {
  return triMaterial[gl_PrimitiveID];
}

// raster_native.vert negates y, which mirrors every triangle: a front face (counter-clockwise in
// the scene's own projection) reaches GL clockwise, so GL's front-facing (glFrontFace GL_CCW) is
// the scene's back face
bool fragmentBackFacing() {
  return gl_FrontFacing;
}

vec2 fragmentUv(FragmentData f) {
  return vUv;
}

vec3 fragmentNormal(FragmentData f) {
  return vNormal;
}

// vertex colours: every triangle of a scene that has them (GL's interpolation of an all-white
// triangle is white up to rounding; the exact raster decides per triangle, as the CPU engine)
bool fragmentHasColor() {
  return uVertexColors != 0u;
}

vec4 fragmentColor(FragmentData f) {
  return vColor;
}

// window depth (glDepthRange 0..1: z_ndc / 2 + 1/2), clamped to [0, 1] as the exact raster does
float fragmentDepth(FragmentData f) {
  return clamp(gl_FragCoord.z, 0.0, 1.0);
}
