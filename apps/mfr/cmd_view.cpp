// mfr view: an interactive window on a scene (GLFW + Dear ImGui) that renders through the Engine
// interface (--engine gl by default); scriptable for tests (--frames, --screenshot, --script).
#ifdef MFR_HAS_VIEW  // cmake/mfr_view.cmake: with the GL engine, GLFW and Dear ImGui
#include <memory>

#include "commands.hpp"
#include "common.hpp"
#include "mfr/core/image.hpp"
#include "view/viewer.hpp"

namespace mfr::cli {

Runner addViewCommand(CLI::App& app) {
  auto args = std::make_shared<view::ViewerArgs>();
  args->scene.engine = "gl";
  args->scene.width = 512;
  args->scene.height = 512;
  CLI::App* cmd = app.add_subcommand(
      "view", "Interactive viewer: switch methods, drag the budget, see the maps and the error");
  args->scene.add(*cmd, false, true);
  cmd->add_option("scene", args->scene.source,
                  "Scene file (.gltf .glb .obj .ply .json) or procedural:NAME[?k=v&...]");
  cmd->add_flag("--list-methods", args->listMethods,
                "Print the methods the viewer offers and exit");
  cmd->add_option("--method,-m", args->method, presetHelp());
  cmd->add_option("--budget,-M", args->budget, "Memory budget, e.g. 20MB (MB = 2^20 bytes)");
  cmd->add_option("--k", args->k, "Explicit k (otherwise derived from the budget)");
  cmd->add_option("--composite", args->composite, "kbuffer or hybrid (default: the preset's)");
  cmd->add_option("--occupancy-d", args->occupancyD, "+occupancy presets: bucket words d (1-64)");
  cmd->add_option("--max-peels", args->maxPeels,
                  "peel, dual-peel: at most P geometry passes (default: until none remains)");
  cmd->add_option("--model", args->model, "dkb*: network model (.mfrnn; default: built-in)");
  cmd->add_option("--mode", args->mode,
                  "View: image, depth, kmap, importance, truth, flip or wiper (default image)");
  cmd->add_option("--frames", args->frames, "Render N frames, then exit (tests)");
  cmd->add_option("--screenshot", args->screenshot,
                  "On the last frame, write the image area (no panel) as PNG");
  cmd->add_flag("--screenshot-ui", args->screenshotUi, "--screenshot includes the panel");
  cmd->add_option("--script", args->script,
                  "JSON list of UI actions applied one per frame (see apps/mfr/view/script.hpp)");
  cmd->add_option("--render-thread", args->renderThread,
                  "Render on a worker thread so the window stays responsive: on, off or auto "
                  "(default: on when interactive, off for --frames/--script)")
      ->check(CLI::IsMember({"on", "off", "auto"}));
  cmd->add_option("--stats-json", args->statsJson,
                  "At exit, write each render's and each screenshot's statistics as JSON");
  return [args] {
    if (!args->listMethods && args->scene.source.empty())
      return fail("view: a scene is needed (e.g. procedural:bottles)");
    if (auto distinct = checkDistinctOutputs(
            {{"--screenshot", args->screenshot}, {"--stats-json", args->statsJson}});
        !distinct)
      return fail(distinct.error().message);
    if (!args->screenshot.empty())
      if (auto format =
              imageOutputFormat("--screenshot", args->screenshot, {OutputImageFormat::Png});
          !format)
        return fail(format.error().message);
    return view::runViewer(*args);
  };
}

}  // namespace mfr::cli
#endif  // MFR_HAS_VIEW
