#include "partita/dem/lammps_data.hpp"

#include "partita/dem/error.hpp"
#include "partita/dem/particles.hpp"

#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <type_traits>
#include <unordered_map>

namespace partita::dem {

namespace {

std::string strip(const std::string& line) {
  std::string s = line.substr(0, line.find('#'));
  const auto b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return {};
  const auto e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

// The whitespace-separated numbers of a data line, read in order with std::from_chars (correctly
// rounded, as the stream's strtod is, at a fraction of an istringstream's cost a line). A field
// must end at whitespace or at the line's end ("0.3abc" is no number); a leading '+' is taken;
// a value must be finite.
class Fields {
 public:
  explicit Fields(const std::string& s) : p_(s.data()), end_(s.data() + s.size()) {}
  template <class T>
  bool next(T& value) {
    while (p_ != end_ && std::isspace(static_cast<unsigned char>(*p_))) ++p_;
    if (p_ == end_) return false;
    if (*p_ == '+') ++p_;
    const auto [q, ec] = std::from_chars(p_, end_, value);
    if (ec != std::errc() || (q != end_ && !std::isspace(static_cast<unsigned char>(*q))))
      return false;
    p_ = q;
    if constexpr (std::is_floating_point_v<T>) return std::isfinite(value);
    return true;
  }
  template <class... T>
  bool read(T&... values) {
    return (next(values) && ...);
  }

 private:
  const char* p_;
  const char* end_;
};

// Appends x in its shortest form that reads back as the same double.
void put(std::string& out, double x) {
  std::array<char, 32> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), x);
  out.append(buf.data(), r.ptr);
}

void put(std::string& out, std::int64_t x) {
  std::array<char, 24> buf{};
  const auto r = std::to_chars(buf.data(), buf.data() + buf.size(), x);
  out.append(buf.data(), r.ptr);
}

}  // namespace

LammpsData LammpsData::of(const Particles& p, const std::vector<double>& material_density) {
  LammpsData d;
  const std::size_t n = p.size();
  d.box_lo = Eigen::Vector3d::Constant(n ? 1e300 : 0.0);
  d.box_hi = Eigen::Vector3d::Constant(n ? -1e300 : 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double r = p.radius[i];
    const double volume = 4.0 / 3.0 * std::numbers::pi * r * r * r;
    const double rho = material_density.at(static_cast<std::size_t>(p.material[i]));
    // the same expression as System::add_particle(): equal masses mean the material's density
    const double m_material = rho * 4.0 / 3.0 * std::numbers::pi * r * r * r;
    d.id.push_back(p.id[i]);
    d.type.push_back(p.material[i] + 1);
    d.diameter.push_back(2.0 * r);
    d.density.push_back(p.mass[i] == m_material ? rho : p.mass[i] / volume);
    d.position.push_back(p.position[i]);
    d.velocity.push_back(p.velocity[i]);
    d.angular_velocity.push_back(p.angular_velocity[i]);
    d.box_lo = d.box_lo.cwiseMin(p.position[i] - Eigen::Vector3d::Constant(r));
    d.box_hi = d.box_hi.cwiseMax(p.position[i] + Eigen::Vector3d::Constant(r));
  }
  return d;
}

void LammpsData::write(const std::string& path, const std::string& title) const {
  std::string out;
  out.reserve(200 * (size() + 1));
  out += title.substr(0, title.find('\n'));
  out += "\n\n";
  put(out, static_cast<std::int64_t>(size()));
  out += " atoms\n";
  int types = 1;
  for (int t : type) types = std::max(types, t);
  put(out, static_cast<std::int64_t>(types));
  out += " atom types\n";
  const char* axes[] = {"x", "y", "z"};
  for (int k = 0; k < 3; ++k) {
    put(out, box_lo[k]);
    out += ' ';
    put(out, box_hi[k]);
    out += std::string(" ") + axes[k] + "lo " + axes[k] + "hi\n";
  }
  out += "\nAtoms # sphere: id type diameter density x y z (SI units)\n\n";
  for (std::size_t i = 0; i < size(); ++i) {
    put(out, id[i]);
    out += ' ';
    put(out, static_cast<std::int64_t>(type[i]));
    for (double v : {diameter[i], density[i], position[i].x(), position[i].y(), position[i].z()}) {
      out += ' ';
      put(out, v);
    }
    out += '\n';
  }
  out += "\nVelocities # id vx vy vz wx wy wz (m/s, rad/s)\n\n";
  for (std::size_t i = 0; i < size(); ++i) {
    put(out, id[i]);
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      put(out, velocity[i][k]);
    }
    for (int k = 0; k < 3; ++k) {
      out += ' ';
      put(out, angular_velocity[i][k]);
    }
    out += '\n';
  }
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw Error("LAMMPS data: cannot write '" + tmp + "'");
    f.write(out.data(), static_cast<std::streamsize>(out.size()));
    f.close();
    if (!f) throw Error("LAMMPS data: writing '" + tmp + "' failed (disk full?)");
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec)
    throw Error("LAMMPS data: cannot rename '" + tmp + "' to '" + path + "': " + ec.message());
}

LammpsData LammpsData::read(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("LAMMPS data: cannot open '" + path + "'");
  LammpsData d;
  long n_atoms = -1;
  std::string line;
  int line_no = 0;
  enum class Section { header, atoms, velocities, other } section = Section::header;
  std::unordered_map<std::int64_t, std::size_t> index_of;
  // the Velocities section: where it starts and which atoms it gave (LAMMPS refuses a partial
  // section: an atom without a line would start at rest without a word)
  int velocities_line = 0;
  std::vector<char> has_velocity;
  std::size_t velocity_lines = 0;
  auto fail = [&](const std::string& what) {
    std::ostringstream msg;
    msg << "LAMMPS data " << path << ":" << line_no << ": " << what << " (line: '" << line << "')";
    throw Error(msg.str());
  };
  std::getline(in, line);  // first line is a title
  ++line_no;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string s = strip(line);
    if (s.empty()) continue;
    if (s == "Atoms" || s.rfind("Atoms ", 0) == 0) {
      section = Section::atoms;
      continue;
    }
    if (s == "Velocities") {
      if (velocities_line > 0)
        fail("a second Velocities section (the first starts at line " +
             std::to_string(velocities_line) + ")");
      section = Section::velocities;
      velocities_line = line_no;
      has_velocity.assign(d.size(), 0);
      continue;
    }
    if (std::isalpha(static_cast<unsigned char>(s[0]))) {
      section = Section::other;  // Masses, Bonds, ...
      continue;
    }
    if (section == Section::header) {
      std::istringstream is(s);
      double a = 0, b = 0;
      std::string k1, k2;
      if (s.find("atoms") != std::string::npos && s.find("types") == std::string::npos) {
        if (!(is >> n_atoms) || n_atoms < 0) fail("cannot read the number of atoms");
      } else if (s.find("xlo xhi") != std::string::npos) {
        if (!(is >> a >> b)) fail("cannot read xlo xhi");
        d.box_lo.x() = a, d.box_hi.x() = b;
      } else if (s.find("ylo yhi") != std::string::npos) {
        if (!(is >> a >> b)) fail("cannot read ylo yhi");
        d.box_lo.y() = a, d.box_hi.y() = b;
      } else if (s.find("zlo zhi") != std::string::npos) {
        if (!(is >> a >> b)) fail("cannot read zlo zhi");
        d.box_lo.z() = a, d.box_hi.z() = b;
      }
      continue;
    }
    if (section == Section::atoms) {
      std::int64_t id = 0;
      int type = 0;
      double dia = 0, rho = 0, x = 0, y = 0, z = 0;
      if (!Fields(s).read(id, type, dia, rho, x, y, z))
        fail("expected 'id type diameter density x y z' (finite numbers)");
      if (!(dia > 0.0)) fail("diameter must be > 0");
      if (!(rho > 0.0)) fail("density must be > 0");
      if (index_of.count(id)) fail("atom id " + std::to_string(id) + " appears twice");
      index_of[id] = d.id.size();
      d.id.push_back(id);
      d.type.push_back(type);
      d.diameter.push_back(dia);
      d.density.push_back(rho);
      d.position.emplace_back(x, y, z);
      d.velocity.emplace_back(Eigen::Vector3d::Zero());
      d.angular_velocity.emplace_back(Eigen::Vector3d::Zero());
    } else if (section == Section::velocities) {
      std::int64_t id = 0;
      double v[6];
      if (!Fields(s).read(id, v[0], v[1], v[2], v[3], v[4], v[5]))
        fail("expected 'id vx vy vz wx wy wz' (finite numbers)");
      const auto it = index_of.find(id);
      if (it == index_of.end()) fail("velocity for unknown atom id " + std::to_string(id));
      if (it->second >= has_velocity.size())
        fail("velocity for atom id " + std::to_string(id) +
             ", which the Atoms section lists only after the Velocities section");
      if (has_velocity[it->second])
        fail("a second velocity line for atom id " + std::to_string(id));
      has_velocity[it->second] = 1;
      ++velocity_lines;
      d.velocity[it->second] = Eigen::Vector3d(v[0], v[1], v[2]);
      d.angular_velocity[it->second] = Eigen::Vector3d(v[3], v[4], v[5]);
    }
  }
  if (n_atoms >= 0 && static_cast<std::size_t>(n_atoms) != d.size()) {
    std::ostringstream msg;
    msg << "LAMMPS data " << path << ": header says " << n_atoms << " atoms, the Atoms section has "
        << d.size();
    throw Error(msg.str());
  }
  if (velocities_line > 0 && velocity_lines != d.size()) {
    std::size_t first = 0;  // the first atom (in file order) without a velocity line
    while (first < d.size() && first < has_velocity.size() && has_velocity[first]) ++first;
    std::ostringstream msg;
    msg << "LAMMPS data " << path << ":" << velocities_line << ": the Velocities section has "
        << velocity_lines << " lines for " << d.size() << " atoms (atom id "
        << (first < d.size() ? d.id[first] : 0)
        << " has none); give one line 'id vx vy vz wx wy wz' per atom, as LAMMPS requires, or "
           "leave the section out for particles at rest";
    throw Error(msg.str());
  }
  return d;
}

}  // namespace partita::dem
