#include "partita/dem/lammps_data.hpp"

#include "partita/dem/error.hpp"

#include <cctype>
#include <fstream>
#include <sstream>
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

}  // namespace

LammpsData LammpsData::read(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("LAMMPS data: cannot open '" + path + "'");
  LammpsData d;
  long n_atoms = -1;
  std::string line;
  int line_no = 0;
  enum class Section { header, atoms, velocities, other } section = Section::header;
  std::unordered_map<std::int64_t, std::size_t> index_of;
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
      section = Section::velocities;
      continue;
    }
    if (std::isalpha(static_cast<unsigned char>(s[0]))) {
      section = Section::other;  // Masses, Bonds, ...
      continue;
    }
    std::istringstream is(s);
    if (section == Section::header) {
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
      if (!(is >> id >> type >> dia >> rho >> x >> y >> z))
        fail("expected 'id type diameter density x y z'");
      if (!(dia > 0.0)) fail("diameter must be > 0");
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
      if (!(is >> id >> v[0] >> v[1] >> v[2] >> v[3] >> v[4] >> v[5]))
        fail("expected 'id vx vy vz wx wy wz'");
      const auto it = index_of.find(id);
      if (it == index_of.end()) fail("velocity for unknown atom id " + std::to_string(id));
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
  return d;
}

}  // namespace partita::dem
