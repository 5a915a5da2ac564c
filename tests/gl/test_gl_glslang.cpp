// Every shader variant the GL engine can link compiles, also those this machine's driver cannot
// run (the k-buffer capture under each fragment shader interlock extension, the 64-bit atomic
// capture): each composed stage (shaderVariants(), exactly the text the engine hands the driver)
// is validated by glslangValidator (Debian's glslang-tools) as GLSL 4.50 with the extensions the
// variant enables. Needs no GL context. Without glslangValidator the test skips (fails under
// CI=true, where scripts/install-deps.sh installs it).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "gl/shader_sources.hpp"

namespace mfr::gl {
namespace {

std::string run(const std::string& command, int& status) {
  std::string out;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (!pipe) {
    status = -1;
    return out;
  }
  char buffer[4096];
  while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe)) out.append(buffer, n);
  status = pclose(pipe);
  return out;
}

// glslang (12.0, Debian 12) knows GL_ARB_fragment_shader_interlock but not the NV and INTEL
// extensions for desktop GLSL: their variants are validated with the ARB extension standing in
// for the extension line and its functions for theirs; the rest of the text is the variant's own.
std::string withStandIn(std::string source) {
  const auto replace = [&](const std::string& from, const std::string& to) {
    for (size_t at = source.find(from); at != std::string::npos; at = source.find(from, at))
      source.replace(at, from.size(), to), at += to.size();
  };
  const bool intel = source.find("GL_INTEL_fragment_shader_ordering") != std::string::npos;
  replace("#extension GL_NV_fragment_shader_interlock : require",
          "#extension GL_ARB_fragment_shader_interlock : require");
  replace("#extension GL_INTEL_fragment_shader_ordering : require",
          "#extension GL_ARB_fragment_shader_interlock : require\n"
          "layout(pixel_interlock_ordered) in;");
  replace("beginInvocationInterlockNV()", "beginInvocationInterlockARB()");
  replace("endInvocationInterlockNV()", "endInvocationInterlockARB()");
  if (intel) {  // the ordering needs no end; ARB's interlock does, at the end of main
    replace("beginFragmentShaderOrderingINTEL()", "beginInvocationInterlockARB()");
    replace("#define MFR_INTERLOCK_END()\n",
            "#define MFR_INTERLOCK_END() endInvocationInterlockARB()\n");
  }
  return source;
}

TEST(GlShaders, EveryVariantValidatesWithGlslang) {
  int status = 0;
  run("glslangValidator --version", status);
  if (status != 0) {
    const char* ci = std::getenv("CI");
    if (ci && std::string(ci) == "true") FAIL() << "glslangValidator not found (glslang-tools)";
    GTEST_SKIP() << "glslangValidator not found (apt-get install glslang-tools)";
  }
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("mfr_glslang_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  {  // the validator refuses what a driver would: a test of the test
    std::ofstream(dir / "broken.frag") << "#version 450 core\nvoid main() { undefined(); }\n";
    run("glslangValidator " + (dir / "broken.frag").string(), status);
    EXPECT_NE(status, 0);
  }
  const std::vector<ShaderVariant> variants = shaderVariants();
  std::set<std::string> programs;
  std::vector<std::filesystem::path> paths;
  for (const ShaderVariant& v : variants) {
    programs.insert(v.program);
    // the stage from the extension, as glslangValidator reads it
    paths.push_back(dir / (std::to_string(paths.size()) + "." + v.stage));
    std::ofstream(paths.back()) << withStandIn(v.source);
  }
  // in batches (one process per file would cost more than the compiles); a batch that fails is
  // validated file by file, so each failure names its variant
  constexpr size_t kBatch = 64;
  for (size_t begin = 0; begin < paths.size(); begin += kBatch) {
    const size_t end = std::min(paths.size(), begin + kBatch);
    std::string command = "glslangValidator";
    for (size_t i = begin; i < end; ++i) {
      command += ' ';
      command += paths[i].string();
    }
    run(command, status);
    if (status == 0) continue;
    for (size_t i = begin; i < end; ++i) {
      const std::string log = run("glslangValidator " + paths[i].string(), status);
      EXPECT_EQ(status, 0) << variants[i].program << ": " << variants[i].file << "\n" << log;
    }
  }
  EXPECT_GT(variants.size(), 300u);  // the switch combinations are there
  std::cout << "  " << variants.size() << " stages of " << programs.size()
            << " programs validated\n";
  std::filesystem::remove_all(dir);
  // the variants llvmpipe cannot run are among them
  // (each raster program in both rasters: native and exact)
  for (const char* raster : {" [native]", " [exact]"})
    for (const char* p :
         {"capture_kbuffer.frag (lock)", "capture_kbuffer.frag (GL_ARB_fragment_shader_interlock)",
          "capture_kbuffer.frag (GL_NV_fragment_shader_interlock)",
          "capture_kbuffer.frag (GL_INTEL_fragment_shader_ordering)",
          "capture_kbuffer_atomic64.frag (64-bit atomics)", "count.frag"})
      EXPECT_EQ(programs.count(p + std::string(raster)), 1u) << p << raster;
  for (const char* p : {"swap_node_words.comp (64-bit atomics)", "resolve.comp"})
    EXPECT_EQ(programs.count(p), 1u) << p;
  // every shader file the engine embeds is in some variant
  std::set<std::string> files;
  for (const ShaderVariant& v : variants) files.insert(v.file);
  for (size_t i = 0; i < kEmbeddedShaderCount; ++i) {
    const std::string name = kEmbeddedShaders[i].name;
    if (name.ends_with(".glsl") || name.ends_with(".h")) continue;  // included by the others
    EXPECT_EQ(files.count(name), 1u) << name << " is in no variant";
  }
  // and every raster part is composed into some fragment stage
  for (const char* part : {"raster_native.glsl", "raster_exact.glsl", "raster_common.glsl"}) {
    size_t composed = 0;
    for (const ShaderVariant& v : variants)
      composed += v.stage == "frag" && v.source.find(embeddedShader(part)) != std::string::npos;
    EXPECT_GT(composed, 0u) << part;
  }
}

// shared_layout.h's list of the bindings per shader file names exactly the kBind* points each
// embedded shader declares (its own text), and every shader that declares one is listed.
TEST(GlShaders, BindingsListedPerShader) {
  const std::string layout(embeddedShader("shared_layout.h"));
  const size_t begin = layout.find("// Bindings per shader file");
  const size_t end = layout.find("// (end of the bindings per shader file)");
  ASSERT_NE(begin, std::string::npos);
  ASSERT_NE(end, std::string::npos);
  std::map<std::string, std::set<std::string>> listed;
  std::string current;
  std::istringstream lines(layout.substr(begin, end - begin));
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("//   ", 0) != 0) continue;
    std::string rest;
    if (line.rfind("//       ", 0) == 0) {  // continuation
      rest = line.substr(9);
    } else {
      const size_t colon = line.find(": ");
      ASSERT_NE(colon, std::string::npos) << line;
      current = line.substr(5, colon - 5);
      rest = line.substr(colon + 2);
      listed[current];
    }
    std::istringstream words(rest);
    for (std::string w; words >> w;)
      if (w != "-") listed[current].insert(w.substr(0, w.find('(')));
  }
  const std::regex binding(R"(binding = (kBind\w+))");
  size_t declaring = 0;
  for (size_t i = 0; i < kEmbeddedShaderCount; ++i) {
    const std::string name = kEmbeddedShaders[i].name;
    if (name == "shared_layout.h") continue;
    const std::string text = kEmbeddedShaders[i].text;
    std::set<std::string> declared;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), binding);
         it != std::sregex_iterator(); ++it)
      declared.insert((*it)[1].str());
    if (declared.empty() && !listed.contains(name)) continue;  // (raster.vert: no bindings)
    declaring += !declared.empty();
    ASSERT_TRUE(listed.contains(name)) << name << " is not in shared_layout.h's list";
    EXPECT_EQ(listed[name], declared) << name;
  }
  EXPECT_GE(declaring, 25u);
}

}  // namespace
}  // namespace mfr::gl
