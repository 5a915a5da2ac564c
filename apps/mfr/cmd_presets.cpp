// mfr presets: the preset table (src/method/method.cpp) as text, Markdown (the README's table) or
// JSON, so every list of methods a user reads comes from the one table.
#include <cstdio>
#include <memory>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "common.hpp"
#include "mfr/method/method.hpp"

namespace mfr::cli {

Runner addPresetsCommand(CLI::App& app) {
  auto format = std::make_shared<std::string>("text");
  CLI::App* cmd = app.add_subcommand("presets",
                                     "List the method presets (one table: name, paper, "
                                     "summary, compositing rule, +occupancy)");
  cmd->add_option("--format", *format, "text (default), markdown or json")
      ->check(CLI::IsMember({"text", "markdown", "json"}));
  return [format] {
    if (*format == "markdown") {
      std::printf("%s", presetTableMarkdown().c_str());
      return 0;
    }
    nlohmann::json rows = nlohmann::json::array();
    for (const PresetInfo& p : presetTable()) {
      const MethodDesc m = methodPreset(p.name).value();
      rows.push_back({{"name", p.name},
                      {"paper", p.paper},
                      {"summary", p.summary},
                      {"compositing", toString(m.compositing)},
                      {"occupancy", static_cast<bool>(methodPreset(p.name + "+occupancy"))}});
    }
    if (*format == "json") {
      std::printf("%s\n", rows.dump(2).c_str());
      return 0;
    }
    for (const auto& r : rows)
      std::printf("%-15s %s (%s)\n", r["name"].get<std::string>().c_str(),
                  r["summary"].get<std::string>().c_str(), r["paper"].get<std::string>().c_str());
    return 0;
  };
}

}  // namespace mfr::cli
