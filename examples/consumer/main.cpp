// Uses the installed mfr library: loads a scene (a file or procedural:NAME), renders it with two
// presets under one memory budget, prints each run's statistics as one line of JSON and writes
// OUTDIR/PRESET.png.
//
//   mfr_consumer [SCENE [BUDGET [OUTDIR]]]      defaults: procedural:bottles 4MB .
#include <cstdio>
#include <string>

#include <mfr/mfr.hpp>

int main(int argc, char** argv) {
  const std::string source = argc > 1 ? argv[1] : "procedural:bottles";
  const std::string budget = argc > 2 ? argv[2] : "4MB";
  const std::string outDir = argc > 3 ? argv[3] : ".";
  const auto fail = [](const mfr::Error& e) {
    std::fprintf(stderr, "mfr_consumer: %s\n", e.message.c_str());
    return 1;
  };

  auto scene = mfr::loadScene(source);
  if (!scene) return fail(scene.error());
  const mfr::Camera camera =
      scene->defaultCamera.value_or(mfr::frameBounds(mfr::sceneBounds(*scene)));
  auto engine = mfr::makeEngine("cpu");
  if (!engine) return fail(engine.error());
  auto view = (*engine)->prepare({.scene = &*scene, .camera = camera, .width = 256, .height = 256});
  if (!view) return fail(view.error());
  auto bytes = mfr::parseByteSize(budget);
  if (!bytes) return fail(bytes.error());
  for (const std::string preset : {"kplus-dynamic", "dkb"}) {
    auto method = mfr::methodPreset(preset);
    if (!method) return fail(method.error());
    auto out = (*engine)->render(**view, *method,
                                 {.budgetBytes = *bytes, .background = scene->background});
    if (!out) return fail(out.error());
    std::printf("%s\n", mfr::statsToJson(out->stats).dump().c_str());
    auto written = mfr::writePng(outDir + "/" + preset + ".png", mfr::encodeSrgb(out->image));
    if (!written) return fail(written.error());
  }
  return 0;
}
