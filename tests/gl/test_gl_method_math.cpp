// The methods' numeric constants are written once, in method_math.h (shared by the CPU engine and
// the shaders): no shader file repeats one. Every float literal (with a decimal point or an
// exponent) and every hexadecimal literal in method_math.h's code, except the everyday values 0,
// 0.5, 1 and 2, is a method constant; a shader whose code (comments aside) holds a literal of the
// same value fails. Needs no GL context.
#include <gtest/gtest.h>

#include <cstdlib>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "gl/shader_sources.hpp"

namespace mfr::gl {
namespace {

// The text without its // and /* */ comments.
std::string withoutComments(const std::string& text) {
  std::string out;
  for (size_t i = 0; i < text.size();) {
    if (text.compare(i, 2, "//") == 0) {
      i = text.find('\n', i);
      if (i == std::string::npos) break;
    } else if (text.compare(i, 2, "/*") == 0) {
      const size_t end = text.find("*/", i + 2);
      i = end == std::string::npos ? text.size() : end + 2;
    } else {
      out += text[i++];
    }
  }
  return out;
}

// Float literals (decimal point or exponent) and hexadecimal literals, as values; a float value
// is kept as the double it names, a hexadecimal one as its integer (negative: apart).
struct Literals {
  std::set<double> floats;
  std::set<unsigned long long> hex;
};
Literals literalsOf(const std::string& code) {
  Literals out;
  static const std::regex number(
      R"((^|[^\w.])(0[xX][0-9a-fA-F]+|(\d+\.\d*|\.\d+)([eE][-+]?\d+)?|\d+[eE][-+]?\d+)((lf|LF|[fFuU])?)(?![\w.]))");
  for (auto it = std::sregex_iterator(code.begin(), code.end(), number);
       it != std::sregex_iterator(); ++it) {
    const std::string token = (*it)[2].str();
    if (token.size() > 2 && (token[1] == 'x' || token[1] == 'X'))
      out.hex.insert(std::strtoull(token.c_str(), nullptr, 16));
    else
      out.floats.insert(std::strtod(token.c_str(), nullptr));
  }
  return out;
}

// The method constants: method_math.h's literals less the everyday values.
Literals methodConstants() {
  Literals l = literalsOf(withoutComments(std::string(embeddedShader("method_math.h"))));
  for (double everyday : {0.0, 0.5, 1.0, 2.0}) l.floats.erase(everyday);
  l.floats.insert(1e-12);  // kMboitTiny, written there as a quotient of integers
  return l;
}

// "value (token)" of each method constant in `code`
std::vector<std::string> repeatedConstants(const std::string& code, const Literals& constants) {
  std::vector<std::string> found;
  const Literals l = literalsOf(withoutComments(code));
  for (double v : l.floats)
    if (constants.floats.contains(v)) found.push_back(std::to_string(v));
  for (unsigned long long v : l.hex)
    if (constants.hex.contains(v)) found.push_back(std::to_string(v));
  return found;
}

TEST(GlShaders, MethodConstantsOnlyInMethodMath) {
  ASSERT_FALSE(embeddedShader("method_math.h").empty());
  const Literals constants = methodConstants();
  // the header holds the constants of every method it shares
  // (as the doubles their decimal spellings name)
  for (double v : {1e-2, 3e3, 1e-4, 5e4, 5e-7, 0.99999, 0.375, 0.25, 1.1, 16777216.0, 8.0, 1.001})
    EXPECT_TRUE(constants.floats.contains(v)) << v;
  for (unsigned long long v : {0x1CE4E5B9ull, 0xBF58476Dull, 0x133111EBull, 0x94D049BBull})
    EXPECT_TRUE(constants.hex.contains(v)) << v;
  // a test of the test: a repeated weight clamp is found, in any spelling, and comments are not
  // code
  EXPECT_EQ(repeatedConstants("float w = max(1e-2, 3000.0 * t);", constants).size(), 2u);
  EXPECT_EQ(repeatedConstants("float w = max(0.01f, t); // 3e3\n/* 5e4 */", constants).size(), 1u);
  EXPECT_TRUE(
      repeatedConstants("float a = 1.0 - 0.5 * x + 2.0; uint s = x >> 8u;", constants).empty());
  size_t shaders = 0;
  for (size_t i = 0; i < kEmbeddedShaderCount; ++i) {
    const std::string name = kEmbeddedShaders[i].name;
    if (name == "method_math.h") continue;
    ++shaders;
    const std::vector<std::string> found = repeatedConstants(kEmbeddedShaders[i].text, constants);
    std::string list;
    for (const std::string& v : found) list += " " + v;
    EXPECT_TRUE(found.empty()) << name << " repeats method_math.h's constant(s)" << list;
  }
  EXPECT_GE(shaders, 30u);
}

}  // namespace
}  // namespace mfr::gl
