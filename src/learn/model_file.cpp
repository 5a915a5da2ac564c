// The model file (.mfrnn): see mfr/learn/model_file.hpp for the layout. Integers and floats are
// written byte by byte in little-endian order from their bit patterns (std::bit_cast), so a float's
// bits, NaN payloads and negative zero included, round-trip exactly on any host. Reading validates
// in file order (magic, version, layer count, sizes, length, parameters, metadata) and reports the
// first problem as "<name>: <problem>".
#include "mfr/learn/model_file.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <concepts>
#include <cstring>
#include <string_view>

#include "mfr/core/atomic_file.hpp"
#include "mfr/core/file_access.hpp"
#include "mfr/core/json_limits.hpp"
#include "mfr/core/quote.hpp"

namespace mfr::learn {
namespace {

constexpr uint8_t kMagic[8] = {'M', 'F', 'R', 'M', 'L', 'P', 0, 0};
constexpr uint32_t kMaxLayers = 16;
constexpr uint32_t kMaxLayerSize = 4096;
constexpr uint32_t kMaxMetadata = 1u << 20;
constexpr size_t kFixedHeader = 16;  // magic, version, layer count

/// The largest valid file: kMaxLayers layers of kMaxLayerSize x kMaxLayerSize, longest metadata.
constexpr size_t kMaxFileBytes =
    kFixedHeader + 4 * (kMaxLayers + 1) +
    size_t{kMaxLayers} * 4 * (size_t{kMaxLayerSize} * kMaxLayerSize + kMaxLayerSize) + 4 +
    kMaxMetadata;

// --- messages ---------------------------------------------------------------------------------

void append(std::string& s, std::string_view part) {
  s += part;
}
template <std::integral T>
void append(std::string& s, T value) {
  s += std::to_string(value);
}
void append(std::string& s, float value) {
  s += std::to_string(value);
}

/// Concatenates strings and numbers (and avoids GCC 12's false -Wrestrict on "lit" + string).
template <typename... Parts>
std::string cat(const Parts&... parts) {
  std::string s;
  (append(s, parts), ...);
  return s;
}

template <typename... Parts>
Error fail(const std::string& name, const Parts&... parts) {
  return makeError(cat(echoPath(name), ": ", parts...));  // a path of any length, cut
}

std::string truncated(size_t expected, size_t actual, bool atLeast) {
  return cat("truncated: expected ", atLeast ? "at least " : "", expected, " bytes, got ", actual);
}

// --- bytes ------------------------------------------------------------------------------------

/// Writes into a buffer sized beforehand (GCC 12 gives a false -Wstringop-overflow on
/// vector::insert after reserve, so nothing here grows the vector).
struct Writer {
  uint8_t* p;
  void u32(uint32_t v) {
    for (int i = 0; i < 4; ++i) *p++ = static_cast<uint8_t>(v >> (8 * i));
  }
  void f32(float f) { u32(std::bit_cast<uint32_t>(f)); }
  void raw(const void* data, size_t size) {
    if (size > 0) std::memcpy(p, data, size);
    p += size;
  }
};

uint32_t getU32(const uint8_t* p) {
  return uint32_t{p[0]} | uint32_t{p[1]} << 8 | uint32_t{p[2]} << 16 | uint32_t{p[3]} << 24;
}

float getF32(const uint8_t* p) {
  return std::bit_cast<float>(getU32(p));
}

/// Bytes of layer l's parameters (weights and biases).
size_t layerBytes(const std::vector<int>& sizes, size_t l) {
  const size_t in = static_cast<size_t>(sizes[l]), out = static_cast<size_t>(sizes[l + 1]);
  return 4 * (out * in + out);
}

// --- validation shared by reading and writing ---------------------------------------------------

/// The first non-finite parameter, as a problem, or "". Layers are numbered from 0.
std::string parameterProblem(const Mlp& net) {
  const size_t layers = net.weights.size();
  for (size_t l = 0; l < layers; ++l) {
    const Eigen::MatrixXf& w = net.weights[l];
    for (Eigen::Index r = 0; r < w.rows(); ++r) {
      for (Eigen::Index c = 0; c < w.cols(); ++c) {
        if (!std::isfinite(w(r, c))) {
          return cat("non-finite weight ", w(r, c), " in layer ", l, " (0-based, of ", layers,
                     " layers) at output ", r, ", input ", c);
        }
      }
    }
    const Eigen::VectorXf& b = net.biases[l];
    for (Eigen::Index r = 0; r < b.size(); ++r) {
      if (!std::isfinite(b(r))) {
        return cat("non-finite bias ", b(r), " in layer ", l, " (0-based, of ", layers,
                   " layers) at output ", r);
      }
    }
  }
  return "";
}

/// Shape problem (layer count or a size out of the file's range), or "".
std::string shapeProblem(const std::vector<int>& sizes) {
  if (sizes.size() < 2 || sizes.size() - 1 > kMaxLayers) {
    return cat("layer count ", sizes.size() - 1, " out of range 1..", kMaxLayers);
  }
  for (size_t i = 0; i < sizes.size(); ++i) {
    if (sizes[i] < 1 || static_cast<uint32_t>(sizes[i]) > kMaxLayerSize) {
      return cat("layer size ", sizes[i], " (sizes[", i, "]) out of range 1..", kMaxLayerSize);
    }
  }
  return "";
}

// --- decoding steps ---------------------------------------------------------------------------

/// Reads layer l's weights (row-major) and biases starting at `p`.
void readLayer(const uint8_t* p, Mlp& net, size_t l) {
  const int in = net.sizes[l], out = net.sizes[l + 1];
  Eigen::MatrixXf w(out, in);
  for (int r = 0; r < out; ++r) {
    for (int c = 0; c < in; ++c, p += 4) w(r, c) = getF32(p);
  }
  Eigen::VectorXf b(out);
  for (int r = 0; r < out; ++r, p += 4) b(r) = getF32(p);
  net.weights.push_back(std::move(w));
  net.biases.push_back(std::move(b));
}

/// Checks the magic, version and layer count and reads the sizes; `offset` ends after the sizes.
Result<std::vector<int>> decodeHeader(const uint8_t* bytes, size_t size, const std::string& name,
                                      size_t& offset) {
  if (size > 0 && std::memcmp(bytes, kMagic, std::min(size, sizeof kMagic)) != 0) {
    return fail(name, "not an mfr model file (wrong magic; expected \"MFRMLP\\0\\0\")");
  }
  if (size < kFixedHeader) return fail(name, truncated(kFixedHeader, size, true));
  const uint32_t version = getU32(bytes + 8);
  if (version != kModelVersion) {
    return fail(name, "unsupported model version ", version, " (this build reads version ",
                kModelVersion, ")");
  }
  const uint32_t layers = getU32(bytes + 12);
  if (layers < 1 || layers > kMaxLayers) {
    return fail(name, "layer count ", layers, " out of range 1..", kMaxLayers);
  }
  offset = kFixedHeader + 4 * (size_t{layers} + 1);
  if (size < offset) return fail(name, truncated(offset, size, true));
  std::vector<int> sizes;
  for (uint32_t i = 0; i <= layers; ++i) {
    const uint32_t s = getU32(bytes + kFixedHeader + 4 * i);
    if (s < 1 || s > kMaxLayerSize) {
      return fail(name, "layer size ", s, " (sizes[", i, "]) out of range 1..", kMaxLayerSize);
    }
    sizes.push_back(static_cast<int>(s));
  }
  return sizes;
}

}  // namespace

std::string metadataProblem(std::string_view metadata) {
  if (metadata.size() > kMaxMetadata) {
    return cat("metadata too long: ", metadata.size(), " bytes (at most ", kMaxMetadata, ")");
  }
  const size_t bad = invalidUtf8At(metadata);
  if (bad != std::string_view::npos) {
    return cat("metadata is not valid UTF-8 (at byte ", bad, " of ", metadata.size(), ")");
  }
  if (std::string deep = jsonDepthProblem(metadata); !deep.empty()) return "metadata: " + deep;
  return "";
}

std::vector<uint8_t> encodeModel(const Model& model) {
  const Mlp& net = model.net;
  checkShapes(net);
  size_t total = kFixedHeader + 4 * net.sizes.size() + 4 + model.metadata.size();
  for (size_t l = 0; l < net.weights.size(); ++l) total += layerBytes(net.sizes, l);
  std::vector<uint8_t> out(total);
  Writer put{out.data()};
  put.raw(kMagic, sizeof kMagic);
  put.u32(kModelVersion);
  put.u32(static_cast<uint32_t>(net.weights.size()));
  for (int s : net.sizes) put.u32(static_cast<uint32_t>(s));
  for (size_t l = 0; l < net.weights.size(); ++l) {
    const Eigen::MatrixXf& w = net.weights[l];
    for (Eigen::Index r = 0; r < w.rows(); ++r) {
      for (Eigen::Index c = 0; c < w.cols(); ++c) put.f32(w(r, c));
    }
    for (Eigen::Index r = 0; r < net.biases[l].size(); ++r) put.f32(net.biases[l](r));
  }
  put.u32(static_cast<uint32_t>(model.metadata.size()));
  put.raw(model.metadata.data(), model.metadata.size());
  MFR_CHECK(put.p == out.data() + out.size());
  return out;
}

Result<Model> decodeModel(const uint8_t* bytes, size_t size, const std::string& name) {
  size_t offset = 0;
  auto sizes = decodeHeader(bytes, size, name, offset);
  if (!sizes) return sizes.error();
  Model model;
  model.net.sizes = std::move(sizes.value());
  const size_t layers = model.net.sizes.size() - 1;
  size_t metadataAt = offset;  // where the metadata length is
  for (size_t l = 0; l < layers; ++l) metadataAt += layerBytes(model.net.sizes, l);
  if (size < metadataAt + 4) return fail(name, truncated(metadataAt + 4, size, true));
  const uint32_t metadataBytes = getU32(bytes + metadataAt);
  if (metadataBytes > kMaxMetadata) {
    return fail(name, "metadata length ", metadataBytes, " bytes exceeds the limit of ",
                kMaxMetadata);
  }
  const size_t expected = metadataAt + 4 + metadataBytes;
  if (size < expected) return fail(name, truncated(expected, size, false));
  if (size > expected) {
    return fail(name, size - expected, " trailing bytes after the end of the model (expected ",
                expected, " bytes, got ", size, ")");
  }
  for (size_t l = 0; l < layers; ++l) {
    readLayer(bytes + offset, model.net, l);
    offset += layerBytes(model.net.sizes, l);
  }
  if (std::string problem = parameterProblem(model.net); !problem.empty()) {
    return fail(name, problem);
  }
  model.metadata.assign(reinterpret_cast<const char*>(bytes + metadataAt + 4), metadataBytes);
  if (std::string problem = metadataProblem(model.metadata); !problem.empty()) {
    return fail(name, problem);
  }
  return model;
}

Result<void> writeModel(const std::string& path, const Model& model) {
  checkShapes(model.net);
  for (const std::string& problem : {shapeProblem(model.net.sizes), parameterProblem(model.net),
                                     metadataProblem(model.metadata)}) {
    if (!problem.empty()) return fail(path, "cannot write the model: ", problem);
  }
  const std::vector<uint8_t> bytes = encodeModel(model);
  // a temporary file renamed into place: an interrupted write never leaves a truncated model
  return writeFileAtomically(
      path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

Result<Model> readModel(const std::string& path) {
  // opened once, every check on the descriptor (a FIFO, device or directory is refused there)
  auto file = openRegularFile(path, echoPath(path));
  if (!file) return file.error();
  if (file->size() > kMaxFileBytes) {
    return fail(path, "larger than any valid model file (at most ", kMaxFileBytes, " bytes)");
  }
  auto bytes = file->read(kMaxFileBytes);
  if (!bytes) return bytes.error();
  return decodeModel(bytes->data(), bytes->size(), path);
}

}  // namespace mfr::learn
