// mfr's main entry points in one include, for programs that use the library (find_package(mfr),
// target mfr::mfr; or pkg-config mfr). The flow of a frame:
//
//   auto scene = mfr::loadScene("procedural:bottles");            // scene/load.hpp
//   auto engine = mfr::makeEngine("cpu");                          // engine/engine.hpp
//   auto view = (*engine)->prepare({.scene = &*scene, .camera = camera, .width = w, .height = h});
//   auto method = mfr::methodPreset("kplus-dynamic");              // method/method.hpp
//   auto out = (*engine)->render(**view, *method, {.budgetBytes = M});
//   mfr::writePng("out.png", mfr::encodeSrgb(out->image));         // core/image.hpp
//
// (The CPU engine's own entry points, mfr::RasterFrame::build in cpu/raster_frame.hpp and
// mfr::render in cpu/render.hpp, are included too.)
//
// Every fallible call returns a Result<T> (core/result.hpp) whose error message is one line naming
// the input; the library never prints, throws for bad input, or exits. Metrics
// (metrics/image_metrics.hpp, metrics/flip.hpp), comparisons (compare/compare.hpp,
// compare/compare_output.hpp) and the deep k-buffer's learning side (learn/model_file.hpp,
// learn/dataset.hpp, learn/mlp.hpp) are included too. See examples/consumer/main.cpp.
#pragma once

#include "mfr/compare/compare.hpp"
#include "mfr/compare/compare_output.hpp"
#include "mfr/core/colormap.hpp"
#include "mfr/core/image.hpp"
#include "mfr/core/result.hpp"
#include "mfr/core/units.hpp"
#include "mfr/cpu/cpu_engine.hpp"
#include "mfr/cpu/deep_importance.hpp"
#include "mfr/cpu/raster_frame.hpp"
#include "mfr/cpu/render.hpp"
#include "mfr/engine/engine.hpp"
#include "mfr/learn/dataset.hpp"
#include "mfr/learn/mlp.hpp"
#include "mfr/learn/model_file.hpp"
#include "mfr/method/method.hpp"
#include "mfr/method/method_options.hpp"
#include "mfr/method/stats_json.hpp"
#include "mfr/metrics/flip.hpp"
#include "mfr/metrics/image_metrics.hpp"
#include "mfr/scene/camera.hpp"
#include "mfr/scene/load.hpp"
#include "mfr/scene/scene.hpp"
