// The exact raster of the geometry passes (--gl-raster exact; prepended before raster_common.glsl
// with raster.vert + raster.geom): the CPU engine's coverage test, barycentrics, depth and
// attribute interpolation (include/mfr/cpu/raster_frame_impl.hpp), operation for operation and
// `precise`, in double where the CPU engine's integers need it, so that both engines produce the
// same fragments bit for bit. raster.geom hands each triangle's set-up over as flat inputs.
flat in ivec3 gX;
flat in ivec3 gY;
flat in vec3 gZ;
flat in vec3 gInvW;
flat in vec3 gN0;
flat in vec3 gN1;
flat in vec3 gN2;
flat in vec3 gU;
flat in vec3 gV;
flat in vec4 gC0;  // vertex colour / w of each vertex (read when gTopLeft has kTopLeftHasColor)
flat in vec4 gC1;
flat in vec4 gC2;
flat in float gInvArea;
flat in uint gTopLeft;
flat in uint gMaterial;

uniform ivec2 uSize;

struct FragmentData {
  ivec2 px;
  int pixel;
  vec2 pos;  // the pixel's index (its centre: one sample)
  float l0, l1, l2;
};

// The CPU engine's edge functions at the pixel centre, in double (exact: products below 2^51):
// false when the centre is not covered under its fill rule.
bool rasterFragment(out FragmentData f) {
  f.px = ivec2(gl_FragCoord.xy);
  f.pixel = f.px.y * uSize.x + f.px.x;
  f.pos = vec2(f.px);
  const double px0 = double(f.px.x * 256 + 128);
  const double py0 = double(f.px.y * 256 + 128);
  double w[3];
  bool covered = true;
  for (int i = 0; i < 3; ++i) {
    const int a = (i + 1) % 3, b = (i + 2) % 3;
    const double A = double(gY[a] - gY[b]);
    const double B = double(gX[b] - gX[a]);
    precise double wi = B * (py0 - double(gY[a])) + A * (px0 - double(gX[a]));
    const double bias = ((gTopLeft >> uint(i)) & 1u) != 0u ? 0.0lf : -1.0lf;
    covered = covered && wi + bias >= 0.0lf;
    w[i] = wi;
  }
  precise float l1 = float(w[1]) * gInvArea;
  precise float l2 = float(w[2]) * gInvArea;
  precise float l0 = 1.0 - l1 - l2;
  f.l0 = l0;
  f.l1 = l1;
  f.l2 = l2;
  return covered;
}


uint fragmentMaterial() {
  return gMaterial;
}

// the perspective-correct uv: (sum l_i uv_i / w_i) / (sum l_i / w_i)
vec2 fragmentUv(FragmentData f) {
  precise float q = gInvW.x * f.l0 + gInvW.y * f.l1 + gInvW.z * f.l2;
  precise float invQ = 1.0 / q;
  precise vec2 uvq = vec2(gU.x, gV.x) * f.l0 + vec2(gU.y, gV.y) * f.l1 + vec2(gU.z, gV.z) * f.l2;
  precise vec2 uv = uvq * invQ;
  return uv;
}

// Scene::hasVertexColor of the source triangle (raster.geom's flag, TriangleSetup::hasColor)
bool fragmentHasColor() {
  return (gTopLeft & kTopLeftHasColor) != 0u;
}

// the perspective-correct vertex colour: (sum l_i c_i / w_i) / (sum l_i / w_i), as RasterFrame::surface
vec4 fragmentColor(FragmentData f) {
  precise float q = gInvW.x * f.l0 + gInvW.y * f.l1 + gInvW.z * f.l2;
  precise float invQ = 1.0 / q;
  precise vec4 cq = gC0 * f.l0 + gC1 * f.l1 + gC2 * f.l2;
  precise vec4 c = cq * invQ;
  return c;
}

// the view-space normal, unnormalised: sum l_i n_i / w_i (the perspective-correct normal times q,
// the same direction; shading normalises)
vec3 fragmentNormal(FragmentData f) {
  precise float nx = gN0.x * f.l0 + gN1.x * f.l1 + gN2.x * f.l2;
  precise float ny = gN0.y * f.l0 + gN1.y * f.l1 + gN2.y * f.l2;
  precise float nz = gN0.z * f.l0 + gN1.z * f.l1 + gN2.z * f.l2;
  return vec3(nx, ny, nz);
}

// window depth, linear in screen space, clamped to [0, 1]
float fragmentDepth(FragmentData f) {
  precise float dz1 = gZ.y - gZ.x;
  precise float dz2 = gZ.z - gZ.x;
  precise float z = gZ.x + f.l1 * dz1 + f.l2 * dz2;
  return z > 0.0 ? (z < 1.0 ? z : 1.0) : 0.0;
}

// raster.geom culled the back faces at set-up, as the CPU engine does: every fragment here is kept
bool fragmentBackFacing() {
  return false;
}

// the share of the pixel's samples a node covers: the exact raster has one sample
float coverageShare(uint depthBits) {
  return 1.0;
}

// the scene triangle's index: raster.geom passes its input primitive's on (a clipped piece keeps
// its parent's, as the CPU engine's)
uint fragmentPrimitive() {
  return uint(gl_PrimitiveID);
}
