#!/usr/bin/env python3
"""Writes the committed seed inputs of the fuzz targets into fuzz/seeds/TARGET/.

Small, hand-made, valid (and a few deliberately broken) inputs that reach every feature of each
parser: glTF with external / data-URI / buffer-view resources, sparse and normalized accessors,
node hierarchies, transmission, cameras; GLB; OBJ with MTL and textures; PLY in all three formats;
JSON scenes; procedural specs; byte sizes and method names; camera strings; model and dataset files.
The glTF seeds refer to buffer.bin and texture.png, which the targets write next to the input
(fuzz/gltf_helpers.hpp). Run from anywhere: python3 fuzz/make_seeds.py
"""
import base64
import json
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
SEEDS = os.path.join(HERE, "seeds")

FEATURE_SET = "mfr-dkb-features-v1"  # include/mfr/method/dkb_features.hpp kDkbFeatureSet
TARGET_SCALING = ("K_M(p) / max_q K_M(q) per view and budget "
                  "(include/mfr/learn/dataset.hpp)")  # include/mfr/learn/dataset.hpp


def write(target, name, data):
    folder = os.path.join(SEEDS, target)
    os.makedirs(folder, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(folder, name), "wb") as f:
        f.write(data)


def png(width, height, rgba_rows, color_type=6):
    """A PNG (colour type 6 RGBA8 or 2 RGB8) from rows of bytes."""
    def chunk(kind, body):
        return (struct.pack(">I", len(body)) + kind + body +
                struct.pack(">I", zlib.crc32(kind + body) & 0xffffffff))
    raw = b"".join(b"\x00" + row for row in rgba_rows)
    return (b"\x89PNG\r\n\x1a\n" +
            chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, color_type, 0, 0, 0)) +
            chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))


TEXTURE = png(2, 2, [bytes([255, 0, 0, 128, 0, 255, 0, 255]), bytes([0, 0, 255, 64, 255, 255, 255, 0])])

# buffer.bin as fuzz/gltf_helpers.hpp writes it
POSITIONS = struct.pack("<9f", 0, 0, 0, 1, 0, 0, 0, 1, 0)
UVS = struct.pack("<6f", 0, 0, 1, 0, 0, 1)
INDICES = struct.pack("<4H", 0, 1, 2, 0)
BUFFER = POSITIONS + UVS + INDICES  # 68 bytes


def triangle_gltf(buffer_uri, image, extra_material=None, extra=None):
    """A textured triangle: accessors 0 positions, 1 uvs, 2 indices into buffer 0 (BUFFER)."""
    material = {"pbrMetallicRoughness": {"baseColorFactor": [1, 0.5, 0.25, 0.6],
                                         "baseColorTexture": {"index": 0}},
                "alphaMode": "BLEND", "doubleSided": True}
    if extra_material:
        material.update(extra_material)
    doc = {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [{"mesh": 0, "translation": [0, 0, -1], "rotation": [0, 0, 0.3826834, 0.9238795],
                   "scale": [1, 2, 1], "children": [1]},
                  {"mesh": 0, "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0.5, 0, -0.5, 1]},
                  {"camera": 0, "translation": [0, 0, 3]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "TEXCOORD_0": 1},
                                    "indices": 2, "material": 0, "mode": 4}]}],
        "materials": [material],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 33071}],
        "images": [image],
        "cameras": [{"type": "perspective",
                     "perspective": {"yfov": 0.8, "znear": 0.1, "zfar": 100, "aspectRatio": 1}}],
        "buffers": [{"byteLength": len(BUFFER)} if buffer_uri is None else
                    {"uri": buffer_uri, "byteLength": len(BUFFER)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36, "target": 34962},
                        {"buffer": 0, "byteOffset": 36, "byteLength": 24, "byteStride": 8},
                        {"buffer": 0, "byteOffset": 60, "byteLength": 6, "target": 34963}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [0, 0, 0], "max": [1, 1, 0]},
                      {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC2"},
                      {"bufferView": 2, "componentType": 5123, "count": 3, "type": "SCALAR"}],
    }
    if extra:
        extra(doc)
    return doc


def data_uri(mime, data):
    return "data:%s;base64,%s" % (mime, base64.b64encode(data).decode())


def gltf_seeds():
    write("gltf", "external.gltf", json.dumps(triangle_gltf("buffer.bin", {"uri": "texture.png"}), indent=1))

    def sparse_and_more(doc):
        # sparse positions (vertex 2 moved), normalized ubyte uvs, a second primitive without
        # indices, an orthographic camera, transmission, MASK
        doc["buffers"].append({"uri": data_uri("application/octet-stream",
                                               struct.pack("<H2x3f", 2, 0.2, 0.9, 0.1) +
                                               bytes([0, 0, 255, 0, 0, 255, 0, 0]))})
        doc["bufferViews"] += [{"buffer": 1, "byteOffset": 0, "byteLength": 2},
                               {"buffer": 1, "byteOffset": 4, "byteLength": 12},
                               {"buffer": 1, "byteOffset": 16, "byteLength": 6}]
        doc["accessors"] += [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                              "sparse": {"count": 1,
                                         "indices": {"bufferView": 3, "componentType": 5123},
                                         "values": {"bufferView": 4}}},
                             {"bufferView": 5, "componentType": 5121, "normalized": True,
                              "count": 3, "type": "VEC2"}]
        doc["meshes"].append({"primitives": [{"attributes": {"POSITION": 3, "TEXCOORD_0": 4},
                                              "material": 1}]})
        doc["materials"].append({"pbrMetallicRoughness": {"baseColorFactor": [0.2, 0.9, 0.4, 1]},
                                 "alphaMode": "MASK", "alphaCutoff": 0.3,
                                 "extensions": {"KHR_materials_transmission":
                                                {"transmissionFactor": 0.8}}})
        doc["extensionsUsed"] = ["KHR_materials_transmission"]
        doc["nodes"].append({"mesh": 1, "scale": [0.5, 0.5, 0.5]})
        doc["scenes"][0]["nodes"].append(3)
        doc["cameras"].append({"type": "orthographic",
                               "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}})
        doc["nodes"].append({"camera": 1, "translation": [0, 1, 4]})
        doc["scenes"][0]["nodes"].append(4)

    write("gltf", "datauri_sparse.gltf", json.dumps(triangle_gltf(
        data_uri("application/octet-stream", BUFFER),
        {"uri": data_uri("image/png", TEXTURE)}, extra=sparse_and_more), indent=1))
    write("gltf", "minimal.gltf", '{"asset": {"version": "2.0"}}')
    write("gltf", "draco_required.gltf", json.dumps(
        {"asset": {"version": "2.0"}, "extensionsRequired": ["KHR_draco_mesh_compression"]}))

    # GLB: BIN chunk = BUFFER + PNG, the image read through a buffer view
    def glb_doc(doc):
        doc["bufferViews"].append({"buffer": 0, "byteOffset": len(BUFFER), "byteLength": len(TEXTURE)})
        doc["buffers"][0]["byteLength"] = len(BUFFER) + len(TEXTURE)

    doc = triangle_gltf(None, {"bufferView": 3, "mimeType": "image/png"}, extra=glb_doc)
    write("glb", "embedded.glb", glb(doc, BUFFER + TEXTURE))
    doc = triangle_gltf("buffer.bin", {"uri": "texture.png"})
    write("glb", "external.glb", glb(doc, b""))


def glb(doc, binary):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    out = struct.pack("<I", len(js)) + b"JSON" + js
    if binary:
        binary += b"\0" * (-len(binary) % 4)
        out += struct.pack("<I", len(binary)) + b"BIN\0" + binary
    return b"glTF" + struct.pack("<II", 2, 12 + len(out)) + out


def obj_seeds():
    write("obj", "textured_mtl.obj",
          "# quad and a pentagon with a textured, transparent material\n"
          "mtllib scene.mtl\n"
          "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nv 0 0 -1\n"
          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
          "vn 0 0 1\n"
          "g front\nusemtl glass\n"
          "f 1/1/1 2/2/1 3/3/1 4/4/1\n"
          "usemtl tinted\n"
          "f -5/1 -4/2 -1/3\n"
          "s off\no other\nusemtl missing\nf 1//1 3//1 5//1\n"
          "#--mtl--\n"
          "newmtl glass\nKd 0.8 0.9 1.0\nd 0.3\nmap_Kd texture.png\n"
          "newmtl tinted\nKd 1 0.2 0.2\nTr 0.6\nillum 2\n")
    write("obj", "plain.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n")
    write("obj", "polygon_no_mtl.obj",
          "mtllib absent.mtl\nv 0 0 0\nv 2 0 0\nv 3 1 0\nv 1 2 0\nv -1 1 0\nf 1 2 3 4 5\n")
    write("obj", "bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n")
    write("obj", "nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n")


def ply_seeds():
    header = ("ply\nformat {fmt} 1.0\ncomment made by fuzz/make_seeds.py\n"
              "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
              "property float nx\nproperty float ny\nproperty float nz\n"
              "element face 2\nproperty list uchar int vertex_indices\nend_header\n")
    verts = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, -0.5)]
    faces = [(0, 1, 2), (0, 2, 3)]
    body = "".join("%g %g %g 0 0 1\n" % v for v in verts) + "".join(
        "3 %d %d %d\n" % f for f in faces)
    write("ply", "ascii.ply", header.format(fmt="ascii") + body)
    for fmt, end in (("binary_little_endian", "<"), ("binary_big_endian", ">")):
        data = b"".join(struct.pack(end + "6f", *v, 0, 0, 1) for v in verts)
        data += b"".join(struct.pack(end + "B3i", 3, *f) for f in faces)
        write("ply", fmt + ".ply", header.format(fmt=fmt).encode() + data)
    # quads, extra properties and elements, ushort lists, uchar colours
    write("ply", "quads_extra.ply",
          "ply\nformat ascii 1.0\nobj_info generated\nelement vertex 5\n"
          "property double x\nproperty double y\nproperty double z\n"
          "property uchar red\nproperty uchar green\nproperty uchar blue\n"
          "element face 2\nproperty list uchar ushort vertex_indices\n"
          "element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
          "0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n0 1 0 9 9 9\n0.5 0.5 1 1 2 3\n"
          "4 0 1 2 3\n3 0 1 4\n0 1\n")
    write("ply", "truncated.ply", "ply\nformat ascii 1.0\nelement vertex 3\nend_header\n1 2\n")
    xyz = "property float x\nproperty float y\nproperty float z\n"
    write("ply", "tristrips.ply",
          "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz + "element tristrips 1\n"
          "property list int int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n"
          "6 0 1 2 -1 900 901\n")
    write("ply", "face_extra_lists.ply",
          "ply\nformat ascii 1.0\nelement vertex 3\n" + xyz + "property float s\nproperty float t\n"
          "element face 1\nproperty list uchar int vertex_indices\nproperty uchar red\n"
          "property list uchar float texcoord\nend_header\n0 0 0 0 0\n1 0 0 1 0\n1 1 0 1 1\n"
          "3 0 1 2 7 4 0.1 0.2 0.3 0.4\n")


def json_scene_seeds():
    write("json_scene", "full.json", json.dumps(
        {"mesh": "mesh.obj", "alpha": 0.5, "background": [1, 1, 1],
         "cameras": [{"eye": [0, 1, 3], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 45},
                     {"eye": [2, 0, 2], "target": [0.5, 0.5, 0], "near": 0.5, "far": 20}],
         "transmission_alpha_floor": 0.1}, indent=1))
    write("json_scene", "procedural.json",
          '{"mesh": "procedural:layers?k=3&r=1&pd=0.8", "background": [0, 0, 0.1]}')
    write("json_scene", "spheres.json",
          '{"mesh": "procedural:spheres?count=2&detail=4", "alpha": 1}')
    write("json_scene", "bad_key.json", '{"mesh": "mesh.obj", "colour": 1}')
    write("json_scene", "nested.json", '{"mesh": "other.json"}')


def procedural_seeds():
    specs = {
        "layers": "layers?k=2&r=2&pd=0.5&alpha=0.3",
        "hairball": "hairball?strands=5&segments=3&sides=3&radius=0.05&alpha=0.5&seed=7",
        "smoke": "smoke?count=10&size=0.2&alpha=0.2",
        "bottles": "bottles?count=1&segments=6&alpha=0.4",
        "spheres": "spheres?count=3&scale=1&detail=4&alpha=0.3",
        "out_of_range": "layers?k=0",
        "unknown": "teapot?size=2",
        "twice": "smoke?count=1&count=2",
        "too_many": "hairball?strands=1000000",
    }
    for name, spec in specs.items():
        write("procedural", name, spec)


def units_seeds():
    for i, text in enumerate(["20MB", "512KiB", "1.5GB", "4096", "1 k", "0.5mb", "2TB", ".5G",
                              "fkb+occupancy", "kplus-dynamic", "hybrid", "kbuffer"]):
        write("units", "seed%02d" % i, text)


def camera_seeds():
    for i, text in enumerate(["0,0,5,0,0,0", "0,1,3,0,0,0,0,1,0,45", "-1.5e2, +2,3,0,0,0,0,0,1,90",
                              "0.5,0.5,0.2,0.5,0.5,-1,0,1,0,179.9", "1e30,0,0,0,0,0,0,1,0",
                              "0,0,5,0,0,0,0,0,1", "nan,0,5,0,0,0", "1,2,3"]):
        write("camera", "seed%02d" % i, text)


def model_bytes(sizes, weights, metadata):
    out = b"MFRMLP\0\0" + struct.pack("<II", 1, len(sizes) - 1)
    out += b"".join(struct.pack("<I", s) for s in sizes)
    k = 0
    for l in range(len(sizes) - 1):
        n = sizes[l + 1] * sizes[l] + sizes[l + 1]
        out += struct.pack("<%df" % n, *weights[k:k + n])
        k += n
    meta = metadata.encode()
    return out + struct.pack("<I", len(meta)) + meta


def mfrnn_seeds():
    meta = json.dumps({"features": FEATURE_SET, "target": TARGET_SCALING})
    sizes = [12, 4, 1]
    n = 12 * 4 + 4 + 4 + 1
    weights = [((i * 37) % 11 - 5) / 10.0 for i in range(n)]
    write("mfrnn", "dkb_12_4_1.mfrnn", model_bytes(sizes, weights, meta))
    write("mfrnn", "huge_weights.mfrnn", model_bytes(sizes, [3e38 if i % 3 else -3e38 for i in range(n)], meta))
    write("mfrnn", "linear_12_1.mfrnn", model_bytes([12, 1], [0.1] * 13, json.dumps({"features": FEATURE_SET})))
    write("mfrnn", "no_metadata.mfrnn", model_bytes([2, 3, 1], [0.5] * 13, ""))
    write("mfrnn", "wrong_features.mfrnn", model_bytes(sizes, weights, '{"features": "v0"}'))


def mfrds_seeds():
    meta = json.dumps({"features": FEATURE_SET, "target": TARGET_SCALING, "generator": "seed"})
    scenes = [b"procedural:layers", b"procedural:smoke"]
    out = b"MFRDS\0\0\0" + struct.pack("<III", 1, 12, len(scenes))
    out += b"".join(struct.pack("<I", len(s)) + s for s in scenes)
    out += struct.pack("<I", len(meta)) + meta.encode()
    samples = [(0, 0, 0, 5), (0, 1, 2, 17), (1, 0, 4, 3)]
    out += struct.pack("<Q", len(samples))
    for i, (scene, view, step, pixel) in enumerate(samples):
        out += struct.pack("<4I", scene, view, step, pixel)
        out += struct.pack("<12f", *[(i + j) / 13.0 for j in range(12)])
        out += struct.pack("<f", i / 2.0)
    write("mfrds", "three_samples.mfrds", out)
    old = out.replace(FEATURE_SET.encode(), b"mfr-dkb-features-v0")
    write("mfrds", "old_features.mfrds", old)


def png_seeds():
    write("png", "rgba_2x2.png", TEXTURE)
    write("png", "rgb_3x1.png", png(3, 1, [bytes([10, 20, 30, 40, 50, 60, 70, 80, 90])], color_type=2))
    write("png", "not_png.png", b"GIF89a")


def issue29_seeds():
    """The hostile inputs of issue 29 (tests/test_hostile_inputs.cpp), small versions."""
    # GLB whose BIN chunk claims 8 bytes more than the file holds
    doc = triangle_gltf(None, {"bufferView": 0, "mimeType": "image/png"})
    good = glb(doc, BUFFER)
    js_len = struct.unpack_from("<I", good, 12)[0]
    bin_at = 20 + js_len
    write("glb", "issue29_bin_past_end.glb",
          good[:bin_at] + struct.pack("<I", struct.unpack_from("<I", good, bin_at)[0] + 8) +
          good[bin_at + 4:])
    write("glb", "issue29_truncated.glb", good[:-16])

    def required(name):
        return lambda d: d.update({"extensionsUsed": [name], "extensionsRequired": [name]})
    for name in ("KHR_texture_basisu", "EXT_texture_webp", "MFR_unknown"):
        write("gltf", "issue29_requires_%s.gltf" % name,
              json.dumps(triangle_gltf("buffer.bin", {"uri": "texture.png"}, extra=required(name))))
    write("gltf", "issue29_stride.gltf", json.dumps(triangle_gltf(
        "buffer.bin", {"uri": "texture.png"},
        extra=lambda d: d["bufferViews"][1].update({"byteStride": 2147483644}))))
    write("gltf", "issue29_datauri_length.gltf", json.dumps(triangle_gltf(
        data_uri("application/octet-stream", BUFFER), {"uri": "texture.png"},
        extra=lambda d: d["buffers"][0].update({"byteLength": 10 ** 15}))))
    for i, yfov in enumerate((0, -1, 3.14159265358979)):
        write("gltf", "issue29_yfov_%d.gltf" % i, json.dumps(triangle_gltf(
            "buffer.bin", {"uri": "texture.png"},
            extra=lambda d, y=yfov: d["cameras"][0]["perspective"].update({"yfov": y}))))
    text = json.dumps(triangle_gltf("buffer.bin", {"uri": "texture.png"}))
    write("gltf", "issue29_nan_literal.gltf", text.replace('"count": 3', '"count": NaN', 1))
    far = struct.pack("<9f", 0, 0, 0, 1e38, 0, 0, 0, 1e38, 0) + BUFFER[36:]
    write("gltf", "issue29_far_vertices.gltf", json.dumps(triangle_gltf(
        data_uri("application/octet-stream", far), {"uri": "texture.png"})))
    header = (b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + b"IHDR" +
              struct.pack(">IIBBBBB", 60000, 60000, 8, 6, 0, 0, 0) + b"\0" * 4 +
              struct.pack(">I", 0) + b"IEND" + b"\0" * 4)
    write("gltf", "issue29_png_60000.gltf", json.dumps(triangle_gltf(
        "buffer.bin", {"uri": data_uri("image/png", header)})))
    write("png", "issue29_60000.png", header)
    # OBJ: indices beyond 32 bits, a large convex face, a non-convex face past the limit
    body = "v 0 0 0\nv 1 0 0\nv 0 1 0\n"
    write("obj", "issue29_index_wraps.obj", body + "f 1 2 4294967299\n")
    write("obj", "issue29_index_negative.obj", body + "f 1 2 2147483648\n")
    import math
    n = 5000
    disc = "".join("v %.6f %.6f 0\n" % (math.cos(2 * math.pi * i / n), math.sin(2 * math.pi * i / n))
                   for i in range(n))
    write("obj", "issue29_disc_5000.obj", disc + "f " + " ".join(str(i + 1) for i in range(n)) + "\n")
    n = 2048
    star = "".join("v %.6f %.6f 0\n" % ((1 if i % 2 == 0 else 0.5) * math.cos(2 * math.pi * i / n),
                                        (1 if i % 2 == 0 else 0.5) * math.sin(2 * math.pi * i / n))
                   for i in range(n))
    write("obj", "issue29_star_2048.obj", star + "f " + " ".join(str(i + 1) for i in range(n)) + "\n")
    pentagram = "".join("v %.6f %.6f 0\n" % (math.cos(2 * math.pi * (2 * i % 5) / 5),
                                             math.sin(2 * math.pi * (2 * i % 5) / 5)) for i in range(5))
    write("obj", "issue29_pentagram.obj", pentagram + "f 1 2 3 4 5\n")
    # PLY: a header of 20,000 element lines
    write("ply", "issue29_many_elements.ply",
          "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
          "property float z\nelement face 1\nproperty list uchar int vertex_indices\n" +
          "".join("element e%d 0\n" % i for i in range(20000)) +
          "end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")
    # a JSON scene whose mesh name is 100 kB long
    write("json_scene", "issue29_long_mesh_name.json", json.dumps({"mesh": "m" * 100000 + ".obj"}))


def issue49_seeds():
    """The hostile inputs of issue 49 (tests/test_reliability_json.cpp), small versions: JSON
    nested past the 64 levels every reader allows (include/mfr/core/json_limits.hpp), dataset text
    that is not UTF-8, a target outside [0, 1]."""
    def deep(n):
        return "[" * n + "0" + "]" * n

    def with_hole(doc, raw):
        return json.dumps(doc).replace('"@HOLE@"', raw, 1)
    extras = triangle_gltf("buffer.bin", {"uri": "texture.png"},
                           extra=lambda d: d["nodes"][0].update({"extras": "@HOLE@"}))
    write("gltf", "issue49_deep_extras.gltf", with_hole(extras, deep(100)))
    write("gltf", "issue49_extras_at_limit.gltf", with_hole(extras, deep(61)))
    stride = triangle_gltf("buffer.bin", {"uri": "texture.png"},
                           extra=lambda d: d["bufferViews"][1].update({"byteStride": "@HOLE@"}))
    write("gltf", "issue49_deep_stride.gltf", with_hole(stride, deep(100)))
    write("gltf", "issue49_array_stride.gltf", with_hole(stride, deep(3)))
    text = with_hole(triangle_gltf(None, {"bufferView": 0, "mimeType": "image/png"},
                                   extra=lambda d: d["nodes"][0].update({"extras": "@HOLE@"})),
                     deep(100))
    good = glb(triangle_gltf(None, {"bufferView": 0, "mimeType": "image/png"}), BUFFER)
    js_len = struct.unpack_from("<I", good, 12)[0]
    js = text.encode() + b" " * (-len(text) % 4)
    write("glb", "issue49_deep_extras.glb", good[:8] + struct.pack("<I", len(good) - js_len + len(js)) +
          struct.pack("<I", len(js)) + good[16:20] + js + good[20 + js_len:])
    write("json_scene", "issue49_deep_cameras.json",
          '{"mesh": "mesh.obj", "cameras": %s}' % deep(100))
    sizes = [12, 4, 1]
    weights = [0.1] * (12 * 4 + 4 + 4 + 1)
    write("mfrnn", "issue49_deep_metadata.mfrnn",
          model_bytes(sizes, weights, '{"features": %s}' % deep(100)))
    write("mfrnn", "issue49_array_composite.mfrnn",
          model_bytes(sizes, weights, '{"features": "%s", "composite": %s}' % (FEATURE_SET, deep(3))))

    def dataset(scenes, meta, targets):
        out = b"MFRDS\0\0\0" + struct.pack("<IIII", 2, 12, 1, len(scenes))
        out += b"".join(struct.pack("<I", len(s)) + s for s in scenes)
        out += struct.pack("<I", len(meta)) + meta + struct.pack("<Q", len(targets))
        for i, t in enumerate(targets):
            out += struct.pack("<4I", 0, i, 0, i) + struct.pack("<12f", *[j / 12.0 for j in range(12)])
            out += struct.pack("<f", t)
        return out
    meta = json.dumps({"features": FEATURE_SET, "target": TARGET_SCALING}).encode()
    write("mfrds", "issue49_deep_metadata.mfrds",
          dataset([b"procedural:layers"], ('{"features": %s}' % deep(100)).encode(), [0.5]))
    write("mfrds", "issue49_name_not_utf8.mfrds", dataset([b"procedural:\xfflayers"], meta, [0.5]))
    write("mfrds", "issue49_metadata_not_utf8.mfrds",
          dataset([b"procedural:layers"], b'{"note": "\xc3("}', [0.5]))
    write("mfrds", "issue49_target_2.mfrds", dataset([b"procedural:layers"], meta, [0.5, 2.0]))
    write("mfrds", "issue49_valid_v2.mfrds", dataset([b"procedural:layers"], meta, [0.0, 0.5, 1.0]))


def issue49_memory_seeds():
    """Issue 49 rows 4 and 5: small glTFs that expand past any memory limit (refused before they
    are built, tests/test_reliability_memory.cpp)."""
    accessor = {"componentType": 5126, "count": 4194304, "type": "VEC3",
                "min": [0, 0, 0], "max": [0, 0, 0]}
    nodes = [{"mesh": 0, "translation": [i, 0, 0]} for i in range(1024)]
    write("gltf", "issue49_shared_zero_accessor.gltf", json.dumps({
        "asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": list(range(len(nodes)))}],
        "nodes": nodes, "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [accessor]}))
    write("gltf", "issue49_instancing_zero_accessor.gltf", json.dumps({
        "asset": {"version": "2.0"}, "extensionsUsed": ["EXT_mesh_gpu_instancing"], "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "extensions": {"EXT_mesh_gpu_instancing": {
            "attributes": {"TRANSLATION": 1}}}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [accessor, {"componentType": 5126, "count": 4194304, "type": "VEC3"}]}))


def issue49_image_seeds():
    """Images cut short (issue 49): stb_image left the missing texels as heap memory."""
    texels = bytes(range(256)) * 3
    ppm = b"P6\n16 16\n255\n" + texels
    tga = bytes([0, 0, 2]) + bytes(9) + struct.pack("<HH", 16, 16) + bytes([24, 0x20]) + texels
    for name, data in (("ppm", ppm), ("tga", tga)):
        for kind, image in (("whole", data), ("cut", data[:len(data) - 768 + 48])):
            write("gltf", "issue49_%s_%s.gltf" % (name, kind), json.dumps(triangle_gltf(
                "buffer.bin", {"uri": data_uri("image/png", image)})))
    write("gltf", "issue49_ppm_16384.gltf", json.dumps(triangle_gltf(
        "buffer.bin", {"uri": data_uri("image/png", b"P6\n16384 16384\n255\n" + b"\x7f" * 100)})))
    pgm16 = b"P5 16 16 65535\n" + bytes(range(256)) * 2
    write("gltf", "issue49_pgm16.gltf", json.dumps(triangle_gltf(
        "buffer.bin", {"uri": data_uri("image/png", pgm16)})))
    write("png", "issue49_cut_before_iend.png", TEXTURE[:-12])


def issue49_camera_seeds():
    """Issue 49's camera and face inputs (tests/test_reliability_camera.cpp), small versions."""
    def set_perspective(**fields):
        return lambda d: d["cameras"][0]["perspective"].update(fields)
    write("gltf", "issue49_zfar_1e300.gltf", json.dumps(triangle_gltf(
        "buffer.bin", {"uri": "texture.png"}, extra=set_perspective(zfar=1e300))))
    write("gltf", "issue49_znear_1e20.gltf", json.dumps(triangle_gltf(
        "buffer.bin", {"uri": "texture.png"}, extra=set_perspective(znear=1e20))))
    write("gltf", "issue49_yfov_1e-10.gltf", json.dumps(triangle_gltf(
        "buffer.bin", {"uri": "texture.png"}, extra=set_perspective(yfov=1e-10))))

    def cameras_out_of_order(d):
        # file camera 0 placed by the last node, 1 orthographic, 2 placed first, 3 by no node
        d["cameras"] = [{"type": "perspective", "perspective": {"yfov": 0.9, "znear": 0.1}},
                        {"type": "orthographic",
                         "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}},
                        {"type": "perspective", "perspective": {"yfov": 0.5, "znear": 0.1}},
                        {"type": "perspective", "perspective": {"yfov": 0.7}}]
        d["nodes"][2]["camera"] = 2
        d["nodes"] += [{"camera": 1, "translation": [0, 0, 4]},
                       {"camera": 0, "translation": [0, 1, 3]}]
        d["scenes"][0]["nodes"] += [3, 4]
    write("gltf", "issue49_cameras_out_of_order.gltf", json.dumps(triangle_gltf(
        "buffer.bin", {"uri": "texture.png"}, extra=cameras_out_of_order)))
    write("gltf", "issue49_byte_offset_negative.gltf", json.dumps(triangle_gltf(
        "buffer.bin", {"uri": "texture.png"},
        extra=lambda d: d["accessors"][0].update({"byteOffset": -4}))))
    write("gltf", "issue49_sparse_count_negative.gltf", json.dumps(triangle_gltf(
        "buffer.bin", {"uri": "texture.png"},
        extra=lambda d: d["accessors"][0].update({"sparse": {
            "count": -1, "indices": {"bufferView": 2, "componentType": 5123},
            "values": {"bufferView": 0}}}))))
    quad = "v 0 0 0\nv 1 1 0\nv 1 0 0\nv 0 1 0\n"
    write("obj", "issue49_bowtie_quad.obj", quad + "f 1 2 3 4\n")
    write("obj", "issue49_concave_quad.obj", "v 0 0 0\nv 2 0 0\nv 0.5 0.5 0\nv 0 2 0\nf 1 2 3 4\n")
    ply_header = ("ply\nformat ascii 1.0\nelement vertex 4\ncomment inside the element\n"
                  "property float x\nproperty float y\nobj_info between properties\n"
                  "property float z\nelement face 1\ncomment before the list\n"
                  "property list uchar int vertex_indices\nend_header\n")
    write("ply", "issue49_comment_in_element.ply",
          ply_header + "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")
    write("ply", "issue49_bowtie_quad.ply",
          ply_header + "0 0 0\n1 1 0\n1 0 0\n0 1 0\n4 0 1 2 3\n")
    write("json_scene", "issue49_far_3e38.json", json.dumps(
        {"mesh": "mesh.obj", "cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0], "far": 3e38}]}))
    write("json_scene", "issue49_fov_1e-10.json", json.dumps(
        {"mesh": "mesh.obj", "cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0], "fov": 1e-10}]}))
    write("json_scene", "issue49_near_1e20.json", json.dumps(
        {"mesh": "mesh.obj", "cameras": [{"eye": [0, 0, 3], "target": [0, 0, 0], "near": 1e20}]}))
    write("camera", "issue49_fov_1e-10", "0,0,3,0,0,0,0,1,0,1e-10")
    write("camera", "issue49_fov_at_bound", "0,0,3,0,0,0,0,1,0,0.112")


if __name__ == "__main__":
    gltf_seeds()
    obj_seeds()
    ply_seeds()
    json_scene_seeds()
    procedural_seeds()
    units_seeds()
    camera_seeds()
    mfrnn_seeds()
    mfrds_seeds()
    png_seeds()
    issue29_seeds()
    issue49_seeds()
    issue49_memory_seeds()
    issue49_image_seeds()
    issue49_camera_seeds()
    print("seeds written to", SEEDS)
