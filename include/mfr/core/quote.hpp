// Quoting user input inside one-line error messages.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace mfr {

/// `text` in single quotes for an error message: control characters (newlines included) become
/// '?', and text longer than `maxLength` is cut with "...", so the message stays one line.
inline std::string quoteInput(std::string_view text, size_t maxLength = 80) {
  std::string out = "'";
  for (size_t i = 0; i < text.size() && i < maxLength; ++i) {
    const char c = text[i];
    out += (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) ? '?' : c;
  }
  if (text.size() > maxLength) out += "...";
  return out + "'";
}

/// `text` with control characters (newlines included) replaced by '?' and, when longer than
/// `maxLength`, cut with "...": a third-party library's message or a value read from a file that
/// may hold any bytes, made safe for a one-line error.
inline std::string oneLine(std::string_view text, size_t maxLength = std::string_view::npos) {
  std::string out(text.substr(0, maxLength));
  for (char& c : out)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  if (text.size() > maxLength) out += "...";
  return out;
}

/// A path or scene source echoed at the head of an error line ("PATH: ..."), unquoted as the
/// library's messages name files: control characters as '?', cut at 256 characters with "..."
/// (a real path is shorter; an argument or a Python string can be any length).
inline std::string echoPath(std::string_view path) {
  return oneLine(path, 256);
}

}  // namespace mfr
