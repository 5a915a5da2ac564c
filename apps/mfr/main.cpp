// mfr: bounded-memory multi-fragment rendering from the command line. Parses, calls the library,
// reports; every failure is one line on stderr and a non-zero exit.
#include <cstdio>
#include <exception>
#include <new>

#include "commands.hpp"
#ifdef MFR_HAS_GL
#include "mfr/gl/gl_render_engine.hpp"
#endif

int main(int argc, char** argv) {
#ifdef MFR_HAS_GL
  mfr::gl::registerGlEngine();  // --engine gl
#endif
  CLI::App app{"mfr: bounded-memory multi-fragment rendering and order-independent transparency"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "mfr 0.1.0");
  const mfr::cli::Runner render = mfr::cli::addRenderCommand(app);
  const mfr::cli::Runner info = mfr::cli::addInfoCommand(app);
  const mfr::cli::Runner metrics = mfr::cli::addMetricsCommand(app);
  const mfr::cli::Runner compare = mfr::cli::addCompareCommand(app);
  const mfr::cli::Runner dataset = mfr::cli::addDatasetCommand(app);
  const mfr::cli::Runner train = mfr::cli::addTrainCommand(app);
  const mfr::cli::Runner presets = mfr::cli::addPresetsCommand(app);
#ifdef MFR_HAS_VIEW
  const mfr::cli::Runner view = mfr::cli::addViewCommand(app);
#endif
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  try {
    if (app.got_subcommand("render")) return render();
    if (app.got_subcommand("info")) return info();
    if (app.got_subcommand("metrics")) return metrics();
    if (app.got_subcommand("compare")) return compare();
    if (app.got_subcommand("dataset")) return dataset();
    if (app.got_subcommand("train")) return train();
    if (app.got_subcommand("presets")) return presets();
#ifdef MFR_HAS_VIEW
    if (app.got_subcommand("view")) return view();
#endif
  } catch (const std::bad_alloc&) {
    // the memory pre-flights let it through: named, never "std::bad_alloc"
    const auto commands = app.get_subcommands();
    std::fprintf(stderr,
                 "mfr: error: out of memory in 'mfr %s' (smaller --width/--height or budgets, or "
                 "a --memory-limit to refuse such runs before they allocate)\n",
                 commands.empty() ? "" : commands.front()->get_name().c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mfr: error: %s\n", e.what());
    return 1;
  }
  return 2;
}
