// mfr info: what a scene is made of and what an exact A-buffer of it costs.
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "mfr/core/json_limits.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/core/units.hpp"
#include "mfr/method/memory_model.hpp"

namespace mfr::cli {
namespace {

int run(const SceneOptions& o) {
  Progress progress(!o.quiet);
  progress.set("loading " + o.source);
  auto prepared = prepareScene(o);
  if (!prepared) return fail(prepared.error().message);
  const Scene& scene = prepared->scene;
  size_t blend = 0, mask = 0, opaque = 0;
  for (const Material& m : scene.materials)
    (m.alphaMode == AlphaMode::Blend ? blend : m.alphaMode == AlphaMode::Mask ? mask : opaque)++;
  nlohmann::json views = nlohmann::json::array();
  const MemoryModel abuffer = MemoryModel::of(methodPreset("abuffer").value());
  auto engine = makeSceneEngine(o);
  if (!engine) return fail(engine.error().message);
  for (size_t v = 0; v < prepared->cameras.size(); ++v) {
    progress.set("counting fragments", static_cast<int>(v),
                 static_cast<int>(prepared->cameras.size()));
    auto view = (*engine)->prepare(sceneView(*prepared, o, prepared->cameras[v]));
    if (!view) return fail(echoPath(o.source) + ": " + view.error().message);
    auto counted = (*engine)->countFragments(**view);
    if (!counted) return fail(echoPath(o.source) + ": " + counted.error().message);
    const std::vector<uint32_t>& n = counted.value();
    uint64_t total = 0, covered = 0;
    uint32_t maxN = 0;
    for (uint32_t c : n) {
      total += c;
      covered += c > 0;
      maxN = std::max(maxN, c);
    }
    const Camera& c = prepared->cameras[v];
    views.push_back(
        {{"view", v},
         {"camera",
          {{"eye", {c.eye.x, c.eye.y, c.eye.z}},
           {"target", {c.target.x, c.target.y, c.target.z}},
           {"up", {c.up.x, c.up.y, c.up.z}},
           {"fov", c.fovYDegrees}}},
         {"fragments", total},
         {"covered_pixels", covered},
         {"max_depth_complexity", maxN},
         {"mean_depth_complexity", covered ? double(total) / covered : 0.0},
         {"abuffer_bytes", abuffer.overhead((*view)->pixelCount()) + total * kNodeBytes}});
  }
  // the file's cameras as --view N numbers them (fileCamera): the same list, the same index
  nlohmann::json fileCameras = nlohmann::json::array();
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    auto chosen = fileCamera(scene, o.source, static_cast<int>(i));
    const Camera& c = scene.cameras[i];
    nlohmann::json entry = {{"camera", i}};
    if (chosen)
      entry.update({{"eye", {c.eye.x, c.eye.y, c.eye.z}},
                    {"target", {c.target.x, c.target.y, c.target.z}},
                    {"up", {c.up.x, c.up.y, c.up.z}},
                    {"fov", c.fovYDegrees}});
    else
      entry["refused"] = oneLine(scene.cameraProblems[i], 300);
    fileCameras.push_back(entry);
  }
  nlohmann::json j = {{"scene", o.source},
                      {"triangles", scene.triangleCount()},
                      {"vertices", scene.vertexCount()},
                      {"materials", scene.materials.size()},
                      {"materials_blend", blend},
                      {"materials_mask", mask},
                      {"materials_opaque", opaque},
                      {"textures", scene.textures.size()},
                      {"cameras_in_file", scene.cameras.size()},
                      {"file_cameras", fileCameras},
                      {"width", o.width},
                      {"height", o.height},
                      {"engine", (*engine)->describe()},
                      {"views", views}};
  if (o.json) {
    std::printf("%s\n", jsonText(j).c_str());
    return 0;
  }
  if (o.quiet) return 0;
  progress.clear();
  std::printf("scene       %s\n", o.source.c_str());
  std::printf("triangles   %zu (%zu vertices)\n", scene.triangleCount(), scene.vertexCount());
  std::printf("materials   %zu (%zu blend, %zu mask, %zu opaque), %zu textures\n",
              scene.materials.size(), blend, mask, opaque, scene.textures.size());
  std::string engineText;
  for (const auto& [key, value] : (*engine)->describe())
    engineText += (engineText.empty() ? "" : ", ") + key + " " + value;
  std::printf("engine      %s\n", engineText.c_str());
  for (const auto& c : fileCameras)
    if (c.contains("refused"))
      std::printf("camera %-3d  --view %d refused: %s\n", c["camera"].get<int>(),
                  c["camera"].get<int>(), c["refused"].get<std::string>().c_str());
    else
      std::printf("camera %-3d  --view %d: eye %g, %g, %g, fov %g degrees\n",
                  c["camera"].get<int>(), c["camera"].get<int>(), c["eye"][0].get<double>(),
                  c["eye"][1].get<double>(), c["eye"][2].get<double>(), c["fov"].get<double>());
  for (const auto& v : views)
    std::printf(
        "view %-3d    %dx%d: %llu fragments on %llu pixels, depth complexity max %u mean "
        "%.2f, A-buffer %s\n",
        v["view"].get<int>(), o.width, o.height,
        static_cast<unsigned long long>(v["fragments"].get<uint64_t>()),
        static_cast<unsigned long long>(v["covered_pixels"].get<uint64_t>()),
        v["max_depth_complexity"].get<uint32_t>(), v["mean_depth_complexity"].get<double>(),
        formatBytes(v["abuffer_bytes"].get<uint64_t>()).c_str());
  return 0;
}

}  // namespace

Runner addInfoCommand(CLI::App& app) {
  auto options = std::make_shared<SceneOptions>();
  CLI::App* cmd = app.add_subcommand("info", "Scene statistics and A-buffer cost");
  options->add(*cmd, true, true);
  return [options] { return run(*options); };
}

}  // namespace mfr::cli
