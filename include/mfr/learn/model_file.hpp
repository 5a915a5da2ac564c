// The model file (.mfrnn): a versioned little-endian binary holding an Mlp and a JSON description.
//
//   offset  size        field
//   0       8           magic "MFRMLP\0\0"
//   8       4           u32 version (kModelVersion)
//   12      4           u32 L, number of layers (1..16)
//   16      4 (L + 1)   u32 sizes[0..L] (each 1..4096)
//   ...     per layer l: f32 weights[sizes[l+1]][sizes[l]] (row-major: output row, then input),
//                        f32 bias[sizes[l+1]]
//   ...     4           u32 metadata length m (<= 1 MiB)
//   ...     m           UTF-8 JSON metadata (features, target scaling, training command, ...)
//   end     (no trailing bytes)
//
// Every parameter must be finite. Reading checks the magic, the version, the shapes, the exact
// length (truncated or trailing bytes) and the values, and names the file and the problem.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/learn/mlp.hpp"

namespace mfr::learn {

inline constexpr uint32_t kModelVersion = 1;

struct Model {
  Mlp net;
  std::string metadata;  // JSON text
};

std::vector<uint8_t> encodeModel(const Model& model);
/// `name` names the source in error messages (a path, or "built-in model").
Result<Model> decodeModel(const uint8_t* bytes, size_t size, const std::string& name);

Result<void> writeModel(const std::string& path, const Model& model);
Result<Model> readModel(const std::string& path);

}  // namespace mfr::learn
