// bench_vtk: one frame of N DEM particles (default 10^6) with the arrays the DEM adapter writes
// (points, vertex cells, radius, id, velocity, angular_velocity, force), written
//   - the old way: the DEM solver's former ASCII writer (System::write_particles_vtp: the arrays
//     copied into per-array vectors, 12 significant digits through an ostream; kept here as the
//     reference, since the solver no longer writes files),
//   - by the DEM adapter's writer (adapters::write_particles_vtp, interface/vtk_xml) in each format
//   (ascii: shortest round-trip text; binary: appended raw;
//     zlib: appended, compressed blocks, levels 1 and 6), the data arrays in float64 and in
//     float32 (interface/vtk_xml.hpp, Options::precision),
// and prints bytes and seconds (best of --repeat runs, wall and CPU) with ratios against the old
// ASCII. Values: positions uniform in a 0.1 m box, three radii, ids 1..N, velocities, spins and
// forces normally distributed: every mantissa bit random, as in a real frame (the compression
// ratio depends on that); --at-rest sets velocities, spins and forces to zero (the first frame of
// a run), which compresses far better and shortens the ASCII.
//
// usage: bench_vtk [--particles N] [--repeat R] [--dir DIR] [--keep] [--at-rest]

#include <charconv>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "partita/adapters/dem_output.hpp"
#include "partita/dem/particles.hpp"
#include "partita/interface/error.hpp"
#include "partita/interface/vtk_xml.hpp"

namespace fs = std::filesystem;
using namespace partita;

namespace {

using Frame = dem::Particles;  // the arrays the DEM adapter writes

Frame make_frame(std::size_t n, bool at_rest) {
  Frame f;
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> box(0.0, 0.1);
  std::normal_distribution<double> v(0.0, 0.05), w(0.0, 10.0), force(0.0, 1e-3);
  const double radii[3] = {2.0e-3, 1.5625e-3, 1.25e-3};
  for (std::size_t i = 0; i < n; ++i) {
    f.position.emplace_back(box(rng), box(rng), box(rng));
    if (at_rest) {  // the first frame of a run: nothing moves yet
      f.velocity.emplace_back(Eigen::Vector3d::Zero());
      f.angular_velocity.emplace_back(Eigen::Vector3d::Zero());
      f.force.emplace_back(Eigen::Vector3d::Zero());
    } else {
      f.velocity.emplace_back(v(rng), v(rng), v(rng));
      f.angular_velocity.emplace_back(w(rng), w(rng), w(rng));
      f.force.emplace_back(force(rng), force(rng), force(rng));
    }
    f.radius.push_back(radii[i % 3]);
    f.id.push_back(static_cast<std::int64_t>(i + 1));
  }
  return f;
}

// ---- the old writer (solvers/dem/src/vtk_writer.cpp and System::write_particles_vtp, since
// removed), the reference of the ratios --------------------------------------------------
struct OldArray {
  std::string name;
  int components = 1;
  bool integer = false;
  std::vector<double> values;
};

void old_number(std::ostream& out, double v) {
  char buf[40];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 12);
  out.write(buf, r.ptr - buf);
}

void old_ascii(const Frame& p, const std::string& path) {
  const std::size_t n = p.position.size();
  std::vector<OldArray> data(5);
  data[0] = {"radius", 1, false, std::vector<double>(p.radius)};
  data[1] = {"id", 1, true, {}};
  data[2] = {"velocity", 3, false, {}};
  data[3] = {"angular_velocity", 3, false, {}};
  data[4] = {"force", 3, false, {}};
  for (std::size_t i = 0; i < n; ++i) {
    data[1].values.push_back(static_cast<double>(p.id[i]));
    for (int k = 0; k < 3; ++k) {
      data[2].values.push_back(p.velocity[i][k]);
      data[3].values.push_back(p.angular_velocity[i][k]);
      data[4].values.push_back(p.force[i][k]);
    }
  }
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.precision(12);
    out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\" version=\"1.0\" "
           "byte_order=\"LittleEndian\" header_type=\"UInt64\">\n  <PolyData>\n";
    out << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfVerts=\"" << n
        << "\" NumberOfLines=\"0\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">\n";
    out << "      <Points>\n        <DataArray type=\"Float64\" NumberOfComponents=\"3\" "
           "format=\"ascii\">\n";
    for (const Eigen::Vector3d& x : p.position) {
      old_number(out, x.x());
      out << ' ';
      old_number(out, x.y());
      out << ' ';
      old_number(out, x.z());
      out << '\n';
    }
    out << "        </DataArray>\n      </Points>\n      <PointData>\n";
    for (const OldArray& a : data) {
      out << "        <DataArray type=\"" << (a.integer ? "Int64" : "Float64") << "\" Name=\""
          << a.name << "\" NumberOfComponents=\"" << a.components << "\" format=\"ascii\">\n";
      for (std::size_t k = 0; k < a.values.size(); ++k) {
        if (a.integer)
          out << static_cast<std::int64_t>(a.values[k]);
        else
          old_number(out, a.values[k]);
        out << ((k + 1) % a.components == 0 ? '\n' : ' ');
      }
      out << "        </DataArray>\n";
    }
    out << "      </PointData>\n";
    out << "      <Verts>\n        <DataArray type=\"Int64\" Name=\"connectivity\" "
           "format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) out << i << '\n';
    out << "        </DataArray>\n        <DataArray type=\"Int64\" Name=\"offsets\" "
           "format=\"ascii\">\n";
    for (std::size_t i = 0; i < n; ++i) out << i + 1 << '\n';
    out << "        </DataArray>\n      </Verts>\n    </Piece>\n  </PolyData>\n</VTKFile>\n";
    out.flush();
    if (!out) throw Error("writing " + tmp + " failed");
  }
  fs::rename(tmp, path);
}

struct Timing {
  double wall = 1e300, cpu = 1e300;
};

Timing best_of(int repeat, const std::function<void()>& f) {
  Timing t;
  for (int r = 0; r < repeat; ++r) {
    const auto w0 = std::chrono::steady_clock::now();
    const std::clock_t c0 = std::clock();
    f();
    const double cpu = static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
    const double wall =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
    t.wall = std::min(t.wall, wall);
    t.cpu = std::min(t.cpu, cpu);
  }
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  std::size_t n = 1000000;
  int repeat = 3;
  fs::path dir = fs::temp_directory_path() / "partita_bench_vtk";
  bool keep = false, at_rest = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "bench_vtk: " << a << " needs a value\n";
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--particles")
      n = std::stoul(next());
    else if (a == "--repeat")
      repeat = std::max(1, std::stoi(next()));
    else if (a == "--dir")
      dir = next();
    else if (a == "--keep")
      keep = true;
    else if (a == "--at-rest")
      at_rest = true;
    else {
      std::cerr << "usage: bench_vtk [--particles N] [--repeat R] [--dir DIR] [--keep] "
                   "[--at-rest]\n";
      return 2;
    }
  }
  try {
    fs::create_directories(dir);
    const Frame frame = make_frame(n, at_rest);
    struct Line {
      std::string name;
      std::function<void(const std::string&)> write;
    };
    const auto f64 = vtk::Precision::float64, f32 = vtk::Precision::float32;
    auto with = [&](vtk::Format f, int level, vtk::Precision p) {
      return [&frame, f, level, p](const std::string& path) {
        adapters::write_particles_vtp(frame, path, {f, level, 1u << 20, p});
      };
    };
    const std::vector<Line> lines = {
        {"old ascii (main)", [&](const std::string& p) { old_ascii(frame, p); }},
        {"ascii float64", with(vtk::Format::ascii, 1, f64)},
        {"binary float64", with(vtk::Format::binary, 1, f64)},
        {"zlib-1 float64", with(vtk::Format::zlib, 1, f64)},
        {"zlib-6 float64", with(vtk::Format::zlib, 6, f64)},
        {"ascii float32", with(vtk::Format::ascii, 1, f32)},
        {"binary float32", with(vtk::Format::binary, 1, f32)},
        {"zlib-1 float32", with(vtk::Format::zlib, 1, f32)},
    };
    std::printf(
        "# one frame of %zu particles (points, verts, radius, id, velocity, "
        "angular_velocity, force%s), best of %d, files in %s\n",
        n, at_rest ? "; at rest" : "", repeat, dir.string().c_str());
    std::printf("%-18s %14s %9s %9s %11s %11s\n", "format", "bytes", "wall [s]", "cpu [s]",
                "smaller", "faster");
    double ref_bytes = 0.0, ref_wall = 0.0;
    int k = 0;
    for (const Line& l : lines) {
      const std::string path = (dir / ("frame_" + std::to_string(k++) + ".vtp")).string();
      const Timing t = best_of(repeat, [&] { l.write(path); });
      const double bytes = static_cast<double>(fs::file_size(path));
      if (ref_bytes == 0.0) ref_bytes = bytes, ref_wall = t.wall;
      std::printf("%-18s %14.0f %9.3f %9.3f %10.2fx %10.2fx\n", l.name.c_str(), bytes, t.wall,
                  t.cpu, ref_bytes / bytes, ref_wall / t.wall);
      std::fflush(stdout);
      if (!keep) fs::remove(path);
    }
  } catch (const std::exception& e) {
    std::cerr << "bench_vtk: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
