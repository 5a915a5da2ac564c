// Shared geometry shader of the geometry passes: the CPU engine's primitive set-up, operation for
// operation (src/cpu/raster_frame.cpp): trivial reject and Sutherland-Hodgman clipping against
// near, far and the x/y guard band in clip space (float), then per fan triangle the window
// coordinates in double, snapped to 1/256 pixel with llround, back faces culled where the material
// says so, the orientation made positive, the top-left flags and the bounds test. Each fan triangle is emitted at its snapped position (w = 1,
// so GL's own rasterizer covers the same pixel centres) with its set-up as flat outputs, from
// which the fragment shader recomputes the exact integer edge functions and barycentrics.
layout(triangles) in;
// 21 vertices x 46 output components (gl_Position 4, gX..gV 27, gC0..gC2 12, gInvArea, gTopLeft,
// gMaterial) = 966, within GL 4.5's minimum GL_MAX_GEOMETRY_TOTAL_OUTPUT_COMPONENTS of 1024
layout(triangle_strip, max_vertices = 21) out;

in VertexData {
  vec4 clip;
  vec3 normal;
  vec2 uv;
  vec4 color;
} vIn[];

uniform ivec2 uSize;
uniform double uMaxNdc;  // the CPU engine's guard band clamp (method_math.h's kGuardBandMaxNdc)

layout(std430, binding = kBindTriMaterial) readonly buffer TriMaterial {
  uint triMaterial[];
};
layout(std430, binding = kBindMaterials) readonly buffer Materials {
  uint materials[];  // kMaterialWords per material; only the flags are read here
};

flat out ivec3 gX;  // fixed-point window coordinates (1/256 px), y down
flat out ivec3 gY;
flat out vec3 gZ;  // window depth
flat out vec3 gInvW;
flat out vec3 gN0;  // view-space normal / w of each vertex
flat out vec3 gN1;
flat out vec3 gN2;
flat out vec3 gU;  // uv / w
flat out vec3 gV;
flat out vec4 gC0;  // vertex colour / w of each vertex
flat out vec4 gC1;
flat out vec4 gC2;
flat out float gInvArea;
flat out uint gTopLeft;  // edge flags, and kTopLeftHasColor: Scene::hasVertexColor
flat out uint gMaterial;

// kGuardBand: method_math.h (the CPU set-up's)

float planeDistance(vec4 c, int plane) {
  precise float d;
  if (plane == 0) {
    d = c.z + c.w;
  } else if (plane == 1) {
    d = c.w - c.z;
  } else if (plane == 2) {
    d = kGuardBand * c.w + c.x;
  } else if (plane == 3) {
    d = kGuardBand * c.w - c.x;
  } else if (plane == 4) {
    d = kGuardBand * c.w + c.y;
  } else {
    d = kGuardBand * c.w - c.y;
  }
  return d;
}

vec4 pc[kMaxClipVertices];
vec3 pn[kMaxClipVertices];
vec2 puv[kMaxClipVertices];
vec4 pcol[kMaxClipVertices];

int clipPolygon(int count, uint planes) {
  vec4 tc[kMaxClipVertices];
  vec3 tn[kMaxClipVertices];
  vec2 tuv[kMaxClipVertices];
  vec4 tcol[kMaxClipVertices];
  for (int plane = 0; plane < 6 && count > 0; ++plane) {
    if ((planes & (1u << uint(plane))) == 0u) continue;
    int outCount = 0;
    for (int i = 0; i < count; ++i) {
      const int j = (i + 1) % count;
      const float da = planeDistance(pc[i], plane);
      const float db = planeDistance(pc[j], plane);
      if (da >= 0.0) {
        tc[outCount] = pc[i];
        tn[outCount] = pn[i];
        tuv[outCount] = puv[i];
        tcol[outCount] = pcol[i];
        ++outCount;
      }
      if ((da >= 0.0) != (db >= 0.0)) {
        // glm::mix(a, b, t) = a * (1 - t) + b * t
        precise float denom = da - db;
        precise float t = da / denom;
        precise float omt = 1.0 - t;
        precise vec4 c = pc[i] * omt + pc[j] * t;
        precise vec3 n = pn[i] * omt + pn[j] * t;
        precise vec2 uv = puv[i] * omt + puv[j] * t;
        precise vec4 col = pcol[i] * omt + pcol[j] * t;
        tc[outCount] = c;
        tn[outCount] = n;
        tuv[outCount] = uv;
        tcol[outCount] = col;
        ++outCount;
      }
    }
    count = outCount;
    for (int i = 0; i < count; ++i) {
      pc[i] = tc[i];
      pn[i] = tn[i];
      puv[i] = tuv[i];
      pcol[i] = tcol[i];
    }
  }
  return count;
}

// std::llround: half away from zero
int roundHalfAway(double v) {
  precise double a = abs(v);
  precise double f = floor(a);
  precise double r = a - f;
  precise double q = r >= 0.5lf ? f + 1.0lf : f;
  return int(v < 0.0lf ? -q : q);
}

int ceilDiv256(int a) {
  return a >= 0 ? (a + 255) / 256 : -((-a) / 256);
}
int floorDiv256(int a) {
  return a >= 0 ? a / 256 : -((-a + 255) / 256);
}

void setupAndEmit(int i0, int i1, int i2, uint material, bool hasColor) {
  int idx[3] = int[3](i0, i1, i2);
  int x[3], y[3];
  float z[3], invW[3];
  vec3 nW[3];
  vec2 uvW[3];
  vec4 colW[3];
  for (int i = 0; i < 3; ++i) {
    const vec4 c = pc[idx[i]];
    precise double iw = 1.0lf / double(c.w);
    precise double ndcX = double(c.x) * iw;
    precise double ndcY = double(c.y) * iw;
    if (isnan(ndcX) || isinf(ndcX) || isnan(ndcY) || isinf(ndcY) || isnan(iw) || isinf(iw)) return;
    precise double sx = (clamp(ndcX, -uMaxNdc, uMaxNdc) * 0.5lf + 0.5lf) * double(uSize.x);
    precise double sy = (0.5lf - clamp(ndcY, -uMaxNdc, uMaxNdc) * 0.5lf) * double(uSize.y);
    precise double sx256 = sx * 256.0lf;
    precise double sy256 = sy * 256.0lf;
    x[i] = roundHalfAway(sx256);
    y[i] = roundHalfAway(sy256);
    precise double zw = double(c.z) * iw * 0.5lf + 0.5lf;
    z[i] = float(zw);
    invW[i] = float(iw);
    precise vec3 n = pn[idx[i]] * invW[i];
    precise vec2 uv = puv[idx[i]] * invW[i];
    nW[i] = n;
    uvW[i] = uv;
    precise vec4 col = pcol[idx[i]] * invW[i];
    colW[i] = col;
  }
  precise double area = double(x[1] - x[0]) * double(y[2] - y[0]) -
                        double(y[1] - y[0]) * double(x[2] - x[0]);
  if (area == 0.0lf) return;
  // y down: a front face (counter-clockwise in GL's y-up window) has area < 0 here, as in the CPU
  // set-up, which culls its back faces at this same step
  const bool cullBack = (materials[material * kMaterialWords + kMaterialFlagsWord] &
                         kMaterialCullBack) != 0u;
  if (area > 0.0lf && cullBack) return;
  if (area < 0.0lf) {  // a kept face: flip to a positive orientation
    int ti = x[1]; x[1] = x[2]; x[2] = ti;
    ti = y[1]; y[1] = y[2]; y[2] = ti;
    float tf = z[1]; z[1] = z[2]; z[2] = tf;
    tf = invW[1]; invW[1] = invW[2]; invW[2] = tf;
    vec3 t3 = nW[1]; nW[1] = nW[2]; nW[2] = t3;
    vec2 t2 = uvW[1]; uvW[1] = uvW[2]; uvW[2] = t2;
    vec4 t4 = colW[1]; colW[1] = colW[2]; colW[2] = t4;
    area = -area;
  }
  precise double inv = 1.0lf / area;
  const float invArea = float(inv);
  uint topLeft = 0u;
  for (int i = 0; i < 3; ++i) {
    const int a = (i + 1) % 3, b = (i + 2) % 3;
    const int dx = x[b] - x[a], dy = y[b] - y[a];
    if ((dy == 0 && dx > 0) || dy < 0) topLeft |= 1u << uint(i);
  }
  if (hasColor) topLeft |= kTopLeftHasColor;
  const int minX = max(0, ceilDiv256(min(x[0], min(x[1], x[2])) - 128));
  const int minY = max(0, ceilDiv256(min(y[0], min(y[1], y[2])) - 128));
  const int maxX = min(uSize.x - 1, floorDiv256(max(x[0], max(x[1], x[2])) - 128));
  const int maxY = min(uSize.y - 1, floorDiv256(max(y[0], max(y[1], y[2])) - 128));
  if (minX > maxX || minY > maxY) return;
  for (int i = 0; i < 3; ++i) {
    // window x = X / 256 exactly after GL's viewport transform (x_ndc * W/2 + W/2); rows are not
    // flipped: GL row 0 (the first in memory) is the CPU engine's row 0
    precise double ndcOutX = double(x[i]) / (128.0lf * double(uSize.x)) - 1.0lf;
    precise double ndcOutY = double(y[i]) / (128.0lf * double(uSize.y)) - 1.0lf;
    gl_Position = vec4(float(ndcOutX), float(ndcOutY), 0.0, 1.0);
    gX = ivec3(x[0], x[1], x[2]);
    gY = ivec3(y[0], y[1], y[2]);
    gZ = vec3(z[0], z[1], z[2]);
    gInvW = vec3(invW[0], invW[1], invW[2]);
    gN0 = nW[0];
    gN1 = nW[1];
    gN2 = nW[2];
    gU = vec3(uvW[0].x, uvW[1].x, uvW[2].x);
    gV = vec3(uvW[0].y, uvW[1].y, uvW[2].y);
    gC0 = colW[0];
    gC1 = colW[1];
    gC2 = colW[2];
    gInvArea = invArea;
    gTopLeft = topLeft;
    gMaterial = material;
    gl_PrimitiveID = gl_PrimitiveIDIn;  // the scene triangle's index (hashed alpha's prim)
    EmitVertex();
  }
  EndPrimitive();
}

void main() {
  for (int i = 0; i < 3; ++i) {
    pc[i] = vIn[i].clip;
    pn[i] = vIn[i].normal;
    puv[i] = vIn[i].uv;
    pcol[i] = vIn[i].color;
  }
  uint crossed = 0u;
  for (int plane = 0; plane < 6; ++plane) {
    int inside = 0;
    for (int i = 0; i < 3; ++i) inside += planeDistance(pc[i], plane) >= 0.0 ? 1 : 0;
    if (inside == 0) return;
    if (inside < 3) crossed |= 1u << uint(plane);
  }
  const int count = crossed != 0u ? clipPolygon(3, crossed) : 3;
  const uint material = triMaterial[gl_PrimitiveIDIn];
  // Scene::hasVertexColor: some corner is not exactly white (the constant white attribute of a
  // scene without colours never is)
  bool hasColor = false;
  for (int i = 0; i < 3; ++i) hasColor = hasColor || any(notEqual(vIn[i].color, vec4(1.0)));
  for (int i = 1; i + 1 < count; ++i) setupAndEmit(0, i, i + 1, material, hasColor);
}
