// mfr: bounded-memory multi-fragment rendering from the command line. Parses, calls the library,
// reports; every failure is one line on stderr and a non-zero exit.
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <new>
#include <string>
#include <vector>

#include <unistd.h>

#include "commands.hpp"
#include "common.hpp"
#include "mfr/core/quote.hpp"
#include "mfr/core/suggest.hpp"
#ifdef MFR_HAS_GL
#include "mfr/gl/gl_render_engine.hpp"
#endif

namespace {

/// Exit code of command-line syntax errors (an unknown option, a malformed or missing value, no
/// subcommand); errors of the input itself exit 1.
constexpr int kSyntaxErrorExit = 2;

/// A CLI11 parse error as one line: --help and --version print as CLI11 does and exit 0;
/// everything else is "mfr: error: ..." (the echoed input cut short) and kSyntaxErrorExit.
int reportParseError(const CLI::App& app, const CLI::ParseError& e, int argc, char** argv) {
  if (e.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(e);
  const auto commands = app.get_subcommands();
  std::string message = mfr::oneLine(e.what(), 200);
  if (commands.empty() && argc > 1 && argv[1][0] != '-') {  // "mfr rendr ...": name the word
    std::string names;
    std::vector<std::string> known;
    for (const CLI::App* c : app.get_subcommands({})) {
      names += (names.empty() ? "" : ", ") + c->get_name();
      known.push_back(c->get_name());
    }
    const std::string suggestion = mfr::didYouMean(argv[1], known);
    message = "unknown command " + mfr::quoteInput(argv[1]) +
              (suggestion.empty() ? "" : "; " + suggestion) + " (commands: " + names + ")";
  }
  const std::string help =
      commands.empty() ? "mfr --help" : "mfr " + commands.front()->get_name() + " --help";
  std::fprintf(stderr, "mfr: error: %s (see '%s')\n", message.c_str(), help.c_str());
  return kSyntaxErrorExit;
}

/// Flushes stdout (the --json and summary output): a failed write (a full disk, the file-size
/// limit) is an error, not a silently truncated output.
int finishStdout(int code) {
  errno = 0;
  if (std::fflush(stdout) == 0 && !std::ferror(stdout)) return code;
  const int err = errno;
  std::fprintf(stderr, "mfr: error: stdout: write error (%s)\n",
               err != 0 ? std::strerror(err) : "unknown error");
  return code == 0 ? 1 : code;
}

int run(int argc, char** argv) {
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
  mfr::cli::guardIntegerOptions(app);  // --seed -1 or 2^64 refused, not saturated
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return reportParseError(app, e, argc, argv);
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
    // what to try instead, in the options the command takes
    const auto commands = app.get_subcommands();
    const std::string command = commands.empty() ? "" : commands.front()->get_name();
    const bool sceneOptions = command == "render" || command == "info" || command == "compare" ||
                              command == "dataset" || command == "view";
    const char* advice = command == "metrics" ? " (smaller images, or a --memory-limit to refuse "
                                                "such runs before they allocate)"
                         : sceneOptions       ? " (smaller --width/--height or budgets, or a "
                                                "--memory-limit to refuse such runs before they allocate)"
                                              : "";
    std::fprintf(stderr, "mfr: error: out of memory in 'mfr %s'%s\n", command.c_str(), advice);
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "mfr: error: %s\n",
                 mfr::oneLine(e.what(), mfr::cli::kMaxErrorMessage).c_str());
    return 1;
  }
  return kSyntaxErrorExit;
}

}  // namespace

int main(int argc, char** argv) {
  // past the file-size limit (ulimit -f) write() fails with EFBIG, reported as an error, instead
  // of SIGXFSZ killing the process silently
  std::signal(SIGXFSZ, SIG_IGN);
  // stdout (--json, the summary) into a file or pipe is held in one 1 MiB buffer, so that a write
  // error surfaces in finishStdout with its errno: an automatic flush of stdio's default 4 KiB
  // buffer would fail mid-output and leave nothing to name the reason. A terminal keeps its
  // line buffering.
  static char stdoutBuffer[1 << 20];
  if (!::isatty(STDOUT_FILENO)) std::setvbuf(stdout, stdoutBuffer, _IOFBF, sizeof stdoutBuffer);
  return finishStdout(run(argc, argv));
}
