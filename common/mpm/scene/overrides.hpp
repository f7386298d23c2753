#pragma once
/// Private to the scene parser (scene/*.cpp): --set overrides applied to the TOML document
/// before it is read, and the document written back as text (Scene::toml).
#include <toml++/toml.h>

#include <string>

#include "mpm/scene/toml_reader.hpp"

namespace mpm::scene_toml {

/// Applies one "key=value" override to the document; records the nodes it sets in `doc` (so
/// that messages name the --set). Throws InputError for a malformed override.
void apply_override(toml::table& root, const std::string& arg, Doc& doc);

/// The document as TOML text; parsing it again gives the same document.
std::string to_toml(const toml::table& root);

}  // namespace mpm::scene_toml
