// Limits on JSON read from files (glTF and GLB, JSON scenes, model and dataset metadata, view
// scripts). nlohmann::json parses iteratively, but copying, comparing and serialising a value
// recurse once per level of nesting, and so does tinygltf's conversion of a glTF's extras and
// extensions: a file of 40 KB nested 20,000 levels deep overflowed the stack. Every reader checks
// the nesting of the text (jsonDepthProblem) before it converts anything, and an error message
// shows a value read from a file only through jsonExcerpt (bounded, never recursive).
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

#include <nlohmann/json_fwd.hpp>

namespace mfr {

/// The deepest nesting of arrays and objects mfr reads from a file (the top-level value is level
/// 1). glTF's schema with Khronos's extensions nests at most about 10 levels (meshes / primitives /
/// extensions / KHR_materials_variants / mappings / variants), exporters' extras a few (VRM's
/// extension about 10), JSON scenes 4, model and dataset metadata 3: 64 is far beyond any real
/// file and small enough for any recursion on the value (tinygltf, nlohmann's dump and copy) to
/// take a few KB of stack.
inline constexpr int kMaxJsonDepth = 64;

/// "" when the arrays and objects of `text` nest at most kMaxJsonDepth levels deep (or the text
/// stops being JSON first: parsing it reports that), otherwise "JSON nested deeper than 64 levels
/// (arrays and objects)". A SAX pass (nlohmann::json::sax_parse): no DOM, no recursion, and it
/// stops at the first level too deep.
std::string jsonDepthProblem(std::string_view text);

/// A JSON value read from a file, for an error message: a number, boolean or null as JSON, a
/// string as JSON cut to `maxLength` characters (bytes that are not UTF-8 replaced), an array or
/// object by its size ("an array of 3 items"). One line; never serialises a nested value.
std::string jsonExcerpt(const nlohmann::json& value, size_t maxLength = 60);

/// `value` as JSON text for an output mfr writes (stats, info, metrics), indented by `indent`
/// (-1: one line). Strings mfr put in it from the outside (a scene path, a camera's name) may hold
/// bytes that are not UTF-8, which JSON cannot carry: they are written as U+FFFD where nlohmann's
/// plain dump() throws type_error 316.
std::string jsonText(const nlohmann::json& value, int indent = 2);

/// Offset of the first byte of `text` that is not well-formed UTF-8 (RFC 3629: no overlong forms,
/// no surrogates, nothing above U+10FFFF), or npos. JSON text must be UTF-8 (RFC 8259 section 8.1).
size_t invalidUtf8At(std::string_view text);

}  // namespace mfr
