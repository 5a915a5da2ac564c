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
#include <string_view>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/learn/mlp.hpp"

namespace mfr::learn {

inline constexpr uint32_t kModelVersion = 1;

struct Model {
  Mlp net;
  std::string metadata;  // JSON text
};

/// The problem with a model's or dataset's metadata text, or "": longer than 1 MiB, not UTF-8, or
/// JSON nested deeper than kMaxJsonDepth (mfr/core/json_limits.hpp). Reading and writing a model
/// or dataset refuse such metadata, and so does every check that reads a model's metadata.
std::string metadataProblem(std::string_view metadata);

/// The file's bytes for `model` (deterministic: the same model gives the same bytes). The model's
/// shapes must agree with its sizes (checkShapes; a programmer error otherwise).
std::vector<uint8_t> encodeModel(const Model& model);
/// Parses a model from memory. `name` names the source in error messages (a path, or "built-in
/// model"). Errors: bad magic, unsupported version, layer count or sizes out of range, truncated
/// or trailing bytes, non-finite parameters, bad metadata (metadataProblem).
Result<Model> decodeModel(const uint8_t* bytes, size_t size, const std::string& name);

/// Writes encodeModel's bytes. Errors (naming `path`): sizes out of range, non-finite
/// parameters, bad metadata (nothing is written then), or the file cannot be written.
Result<void> writeModel(const std::string& path, const Model& model);
/// Reads and decodes a model file, opened once (openRegularFile: every check on its descriptor);
/// errors as decodeModel's, or the file cannot be opened / read / is not a regular file. Whether
/// the deep k-buffer can use the model is checkDkbModel's question (method/dkb_model.hpp).
Result<Model> readModel(const std::string& path);

}  // namespace mfr::learn
