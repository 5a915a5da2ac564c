// Model files (.mfrnn, include/mfr/learn/model_file.hpp): magic, version, shapes, exact length,
// finite parameters, UTF-8 metadata. A model that decodes must encode back to the same bytes; one
// that fits the deep k-buffer (checkDkbModel: shapes, the metadata's feature set and target) is
// used for a dkb render, so hostile weights (huge, overflowing activations) meet the allocator.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "fuzz_util.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/learn/model_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  auto model = mfr::learn::decodeModel(data, size, "fuzz.mfrnn");
  if (!model) {
    mfr::fuzz::checkError(model.error(), "fuzz.mfrnn");
    return 0;
  }
  const std::vector<uint8_t> encoded = mfr::learn::encodeModel(model.value());
  FUZZ_CHECK(encoded.size() == size && std::equal(encoded.begin(), encoded.end(), data),
             "decode then encode changes the bytes");
  auto fits = mfr::checkDkbModel(model.value(), "fuzz.mfrnn");
  if (!fits) {
    mfr::fuzz::checkError(fits.error(), "fuzz.mfrnn");
    return 0;
  }
  // Large models are slow under ASan and add nothing the small ones do not reach.
  size_t parameters = 0;
  for (const auto& w : model->net.weights) parameters += static_cast<size_t>(w.size());
  if (parameters > 20000) return 0;
  mfr::MethodDesc dkb = mfr::methodPreset("dkb").value();
  dkb.model = std::make_shared<const mfr::learn::Model>(std::move(model.value()));
  const mfr::Scene& scene = mfr::fuzz::smallScene();
  const mfr::Camera camera =
      scene.defaultCamera ? *scene.defaultCamera : mfr::frameBounds(mfr::sceneBounds(scene));
  mfr::fuzz::renderChecked(scene, camera, 10, dkb, 6000);
  dkb.fillUnusedSlots = true;
  mfr::fuzz::renderChecked(scene, camera, 10, dkb, 6000);
  return 0;
}
