#pragma once
// STL triangle meshes: reader (ASCII and binary, detected from the content, not the extension)
// and writers. Vertices shared by triangles are merged when their coordinates are identical, so
// a watertight STL gives a connected mesh.

#include <filesystem>
#include <string>

#include "partita/interface/mesh.hpp"

namespace partita {

/// Read an STL file. Throws partita::Error naming the file (and line for ASCII, triangle index
/// for binary) on: empty or truncated files, syntax errors, NaN or infinite coordinates, and
/// zero-area triangles. `scale` multiplies every coordinate (e.g. 1e-3 for files in mm).
Mesh read_stl(const std::filesystem::path& file, const std::string& name = "", double scale = 1.0);

/// Parse STL content held in memory (`source` names it in messages).
Mesh parse_stl(const std::string& bytes, const std::string& source, const std::string& name = "",
               double scale = 1.0);

/// Write a binary STL (atomically: temporary file, then rename). Coordinates are stored as
/// 32-bit floats, as the format requires.
void write_stl_binary(const std::filesystem::path& file, const Mesh& mesh);

/// Write an ASCII STL (atomically), coordinates with 17 significant digits (exact for doubles).
void write_stl_ascii(const std::filesystem::path& file, const Mesh& mesh);

}  // namespace partita
