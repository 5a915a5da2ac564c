// Limits on JSON read from files (see mfr/core/json_limits.hpp).
#include "mfr/core/json_limits.hpp"

#include <cstdint>

#include <nlohmann/json.hpp>

#include "mfr/core/quote.hpp"

namespace mfr {
namespace {

using nlohmann::json;

/// Counts the nesting of arrays and objects; stops the parse at the first level too deep.
class DepthCounter final : public nlohmann::json_sax<json> {
 public:
  bool tooDeep() const { return tooDeep_; }

  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return enter(); }
  bool key(string_t&) override { return true; }
  bool end_object() override { return leave(); }
  bool start_array(std::size_t) override { return enter(); }
  bool end_array() override { return leave(); }
  bool parse_error(std::size_t, const std::string&, const nlohmann::detail::exception&) override {
    return false;  // not JSON: the parser that reads the value reports it
  }

 private:
  bool enter() {
    tooDeep_ = ++depth_ > kMaxJsonDepth;
    return !tooDeep_;
  }
  bool leave() {
    --depth_;
    return true;
  }
  int depth_ = 0;
  bool tooDeep_ = false;
};

}  // namespace

std::string jsonDepthProblem(std::string_view text) {
  DepthCounter counter;
  try {
    json::sax_parse(text.begin(), text.end(), &counter);
  } catch (const json::exception&) {
    // not JSON: the parser that reads the value reports it
  }
  if (!counter.tooDeep()) return "";
  return "JSON nested deeper than " + std::to_string(kMaxJsonDepth) +
         " levels (arrays and objects)";
}

std::string jsonExcerpt(const json& value, size_t maxLength) {
  const auto count = [](size_t n, const char* one, const char* many) {
    return std::to_string(n) + " " + (n == 1 ? one : many);
  };
  switch (value.type()) {
    case json::value_t::array:
      return "an array of " + count(value.size(), "item", "items");
    case json::value_t::object:
      return "an object of " + count(value.size(), "member", "members");
    case json::value_t::binary:
      return "binary data of " + count(value.get_binary().size(), "byte", "bytes");
    case json::value_t::string: {
      const std::string& text = value.get_ref<const std::string&>();
      const std::string cut =
          json(text.substr(0, maxLength)).dump(-1, ' ', false, json::error_handler_t::replace);
      return oneLine(cut) + (text.size() > maxLength ? "..." : "");
    }
    default:
      return oneLine(value.dump(), maxLength);
  }
}

size_t invalidUtf8At(std::string_view s) {
  size_t i = 0;
  while (i < s.size()) {
    const uint8_t lead = static_cast<uint8_t>(s[i]);
    size_t length = 1;
    uint32_t cp = lead, minimum = 0;
    if (lead >= 0x80) {
      if ((lead & 0xE0) == 0xC0) {
        length = 2, cp = lead & 0x1F, minimum = 0x80;
      } else if ((lead & 0xF0) == 0xE0) {
        length = 3, cp = lead & 0x0F, minimum = 0x800;
      } else if ((lead & 0xF8) == 0xF0) {
        length = 4, cp = lead & 0x07, minimum = 0x10000;
      } else {
        return i;
      }
    }
    if (s.size() - i < length) return i;
    for (size_t k = 1; k < length; ++k) {
      const uint8_t next = static_cast<uint8_t>(s[k + i]);
      if ((next & 0xC0) != 0x80) return i;
      cp = cp << 6 | (next & 0x3F);
    }
    if (cp < minimum || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return i;
    i += length;
  }
  return std::string_view::npos;
}

std::string jsonText(const json& value, int indent) {
  return value.dump(indent, ' ', false, json::error_handler_t::replace);
}

}  // namespace mfr
