#pragma once
// STL triangle meshes: reader (ASCII and binary, detected from the content, not the extension)
// and writers. Vertices shared by triangles are merged when their coordinates are identical, so
// a watertight STL gives a connected mesh.

#include <filesystem>
#include <string>
#include <vector>

#include "partita/interface/mesh.hpp"

namespace partita {

/// Read an STL file. Throws partita::Error naming the file (and line for ASCII, triangle index
/// for binary) on: empty or truncated files, syntax errors, NaN or infinite coordinates, and
/// zero-area triangles. `scale` multiplies every coordinate (e.g. 1e-3 for files in mm).
/// Orientation is checked, not enforced: facets whose stored normal points against their vertex
/// order (right-hand rule), and edges shared by neighbours whose vertex orders disagree (one of
/// them flipped), are reported, with their count and the first few triangle indices (and lines
/// for ASCII): appended to `warnings` when given, else logged as warnings (logger "interface").
/// The triangles keep the file's vertex order.
Mesh read_stl(const std::filesystem::path& file, const std::string& name = "", double scale = 1.0,
              std::vector<std::string>* warnings = nullptr);

/// Parse STL content held in memory (`source` names it in messages).
Mesh parse_stl(const std::string& bytes, const std::string& source, const std::string& name = "",
               double scale = 1.0, std::vector<std::string>* warnings = nullptr);

/// Write a binary STL (atomically: temporary file, then rename). Coordinates are stored as
/// 32-bit floats, as the format requires.
void write_stl_binary(const std::filesystem::path& file, const Mesh& mesh);

/// Write an ASCII STL (atomically), coordinates with 17 significant digits (exact for doubles).
void write_stl_ascii(const std::filesystem::path& file, const Mesh& mesh);

}  // namespace partita
