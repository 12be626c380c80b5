#pragma once
// `partita check FILE`: read a mesh file with the reader a case would use and describe it.

#include <filesystem>
#include <optional>
#include <string>

namespace partita::adapters {

/// If `path` names a mesh format partita reads (.stl: triangle surface; .msh: Gmsh 4.1 volume
/// mesh), read and validate it completely and return a one-paragraph description; throws
/// partita::Error (file, line, what was wrong) on malformed input. std::nullopt for other files.
std::optional<std::string> describe_mesh_file(const std::filesystem::path& path);

}  // namespace partita::adapters
