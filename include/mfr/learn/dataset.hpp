// The deep k-buffer's training set (DHOIT sec. 3.1.1-3.1.2): per-pixel network inputs paired with
// the optimal k-buffer's allocation, over scenes x views x budgets.
//
// Target scaling: the paper's target is K_M(p) / F(M), numbers near 1 / |P| that a sigmoid output
// and a mean-squared loss barely see. The runtime only uses I(p) / sum I, so any per-image factor
// is free; we use t(p) = K_M(p) / max_q K_M(q) over the covered pixels of the same view and budget,
// which spans [0, 1] (the sigmoid's range) and keeps k(p) proportional to t(p). kDkbTargetScaling
// names this definition; datasets and models record it, and mfr train and dkb check it.
//
// File format (.mfrds), little-endian:
//   offset  size   field
//   0       8      magic "MFRDS\0\0\0"
//   8       4      u32 version (kDatasetVersion)
//   12      4      u32 feature count (12)
//   16      4      u32 T, targets per sample: 1 (the importance t(p)), 9 (dkb-curve's curve,
//                  mfr/method/dkb_curve.hpp) or 3 (DFAOIT's colour, mfr/method/dfaoit.hpp)
//   20      4      u32 S, number of scenes (1..65536)
//   ...            S x { u32 length (1..4096), UTF-8 name }
//   ...     4      u32 metadata length m (<= 1 MiB), then m bytes of JSON (how it was generated)
//   ...     8      u64 N, number of samples (<= 2^32)
//   ...            N x (64 + 4 T)-byte samples: u32 scene, u32 view, u32 budget step, u32 pixel,
//                  f32 features[12] (dkb_features.hpp, or dfaoit.hpp's for T = 3), f32
//                  targets[T] (t(p), the curve, or DFAOIT's colour)
//   end            (no trailing bytes)
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "mfr/core/result.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/method/dkb_curve.hpp"
#include "mfr/method/dkb_features.hpp"
#include "mfr/method/method.hpp"

namespace mfr::learn {

inline constexpr uint32_t kDatasetVersion = 2;

/// The target definition (scaling) of sampleView: the one constant `mfr dataset` records in
/// datasets, `mfr train` in models, and checkDkbModel compares ("target"). Change it whenever the
/// target changes, and retrain (scripts/train-model.sh).
inline constexpr const char* kDkbTargetScaling =
    "K_M(p) / max_q K_M(q) per view and budget (include/mfr/learn/dataset.hpp)";

struct DatasetSample {
  uint32_t scene = 0;       // index into Dataset::scenes
  uint32_t view = 0;        // camera index within the scene
  uint32_t budgetStep = 0;  // 0 = one fragment per covered pixel ... steps - 1 = all fragments
  uint32_t pixel = 0;       // y * width + x
  PixelFeatures features{};
  float target = 0.0f;            // the importance target t(p) (Dataset::targetCount 1)
  CurveTargets curve{};           // dkb-curve's targets (Dataset::targetCount 9)
  PixelFeatures curveFeatures{};  // and its inputs (dkbCurveFeatureSet; what a curve file holds)
  std::array<float, 3> colour{};  // DFAOIT's target (Dataset::targetCount 3), features then
                                  // DfaoitPixel::features()
};

/// Targets per sample of a DFAOIT dataset (the colour y, mfr/method/dfaoit.hpp).
inline constexpr uint32_t kDfaoitTargetCount = 3;

struct Dataset {
  std::vector<std::string> scenes;
  uint32_t targetCount = 1;  // 1: DatasetSample::target, kCurveOutputs: DatasetSample::curve,
                             // kDfaoitTargetCount: DatasetSample::colour
  std::string metadata;      // JSON
  std::vector<DatasetSample> samples;
  uint64_t fileHash = 0;  // fnv1a64 of the file's bytes: set by readDataset, ignored when writing
};

/// 64-bit FNV-1a (offset basis 0xcbf29ce484222325, prime 0x100000001b3) of `bytes`: the content
/// hash a model records of each dataset it was trained on.
uint64_t fnv1a64(std::string_view bytes);

/// fnv1a64 as 16 lower-case hex digits.
std::string hashHex(uint64_t hash);

/// What readDataset and writeDataset refuse in one sample (and Python's save_dataset before it
/// builds one): `field` the column it is in ("scene", "features" or "targets"), `text` what is
/// wrong, e.g. "target is 2, outside [0, 1]".
struct SampleProblem {
  const char* field;
  std::string text;
};
/// The first problem of sample `s` in a dataset of `targetCount` targets per sample
/// (Dataset::targetCount) and `sceneCount` scenes: a scene index not below it, a feature that is
/// not finite, a target the file holds (t(p), the curve's or the colour's) outside [0, 1].
std::optional<SampleProblem> datasetSampleProblem(const DatasetSample& s, uint32_t targetCount,
                                                  size_t sceneCount);

/// Writes the .mfrds file. Checked first as readDataset checks (nothing is written then): 1..65536
/// scenes with names of 1..4096 bytes of UTF-8, metadataProblem (model_file.hpp), every sample's
/// datasetSampleProblem. Errors: those, or the file cannot be written.
Result<void> writeDataset(const std::string& path, const Dataset& data);
/// Reads the file, opened once (openRegularFile: every check on its descriptor). Checks magic,
/// version, feature count, lengths, scene names (UTF-8), metadata (metadataProblem), every
/// sample (datasetSampleProblem); errors name path. Sets Dataset::fileHash.
Result<Dataset> readDataset(const std::string& path);

/// Checks that a dataset's metadata, where it declares a feature set ("features") or a target
/// ("target"), declares kDkbFeatureSet and kDkbTargetScaling (kDkbCurveTargetScaling for curve
/// datasets; kDfaoitFeatureSet and kDfaoitTarget for DFAOIT's): a dataset written by an older `mfr
/// dataset` is refused rather than trained on. `path` names it in the message.
Result<void> checkDatasetDefinitions(const Dataset& data, const std::string& path);

/// The compositing rule a dataset's targets were computed for: its metadata's "composite"
/// (absent: hybrid, the only rule before per-rule models). Errors name `path`.
Result<Compositing> datasetRule(const Dataset& data, const std::string& path);

/// F(M) of budget step s of `steps`: from one slot per covered pixel to every fragment, evenly.
uint64_t budgetStepSlots(uint64_t coveredPixels, uint64_t fragments, int step, int steps);

struct ViewSamplingOptions {
  int budgetSteps = 5;
  /// Relative budgets instead of the steps (budget_spec.hpp): step s has F(M) =
  /// floor(budgetPercents[s] / 100 * 8 N) / 8 slots; a share below one slot per covered pixel is
  /// an error naming the smallest share that works.
  std::vector<double> budgetPercents;
  double sampleFraction = 0.2;  // of the covered pixels, per view and budget
  uint64_t seed = 1;
  glm::vec3 background{1.0f};
  /// The compositing rule whose error curves define the optimal targets (kbuffer or hybrid):
  /// one model per rule (issue 14 sec. 3); datasets record it as "composite".
  Compositing compositing = Compositing::Hybrid;
  /// dkb-curve's targets (the curve, DatasetSample::curve) instead of the importance target.
  bool curveTargets = false;
  /// Memory pre-flight of the exact A-buffer and error curves (frameErrorCurves); none: default.
  std::optional<uint64_t> memoryLimitBytes;
};

/// DFAOIT's samples of one rendered view (mfr/method/dfaoit.hpp): for a sampled pixel of at least
/// three fragments of positive alpha (fewer need no network) whose fragments behind the nearest
/// are visible ((1 - a0) - T > 1e-4) (options.sampleFraction, options.seed; budget step 0) its
/// inputs DfaoitPixel::features() and its target y', from the A-buffer's sorted composite C:
/// (C - a0 c0) / ((1 - a0) - T), clamped to [0, 1]. Budgets do not apply (no nodes).
std::vector<DatasetSample> sampleDfaoitView(const RasterFrame& frame, uint32_t scene, uint32_t view,
                                            const ViewSamplingOptions& options);

/// Features and optimal targets of one rendered view, for every budget step, sampled.
Result<std::vector<DatasetSample>> sampleView(const RasterFrame& frame, uint32_t scene,
                                              uint32_t view, const ViewSamplingOptions& options);

}  // namespace mfr::learn
