// The messages between a participant's proxy and its server (remote_messages.hpp).
#include "remote_messages.hpp"

#include <algorithm>
#include <cstring>

namespace partita::run::remote {

bool same_bits(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() &&
         (a.size() == 0 ||
          std::memcmp(a.data(), b.data(), static_cast<std::size_t>(a.size()) * sizeof(double)) == 0);
}

MessageWriter start(std::string& buffer, Command c) {
  buffer.clear();
  MessageWriter out(buffer);
  out.write(static_cast<std::uint32_t>(c));
  return out;
}

void write_mesh(MessageWriter& out, const InterfaceMesh& m) {
  out.write(m.mesh.name());
  out.write(Eigen::MatrixXd(m.mesh.points()));
  std::vector<int> tri(m.mesh.triangles().data(),
                       m.mesh.triangles().data() + m.mesh.triangles().size());
  out.write(tri);
  out.write(m.mesh.weights());
  out.write(static_cast<std::uint8_t>(m.prescribed));
  for (const auto* specs : {&m.reads, &m.writes}) {
    out.write(static_cast<std::uint64_t>(specs->size()));
    for (const DataSpec& d : *specs) {
      out.write(d.name);
      out.write(static_cast<std::int32_t>(d.components));
      out.write(d.unit);
      out.write(static_cast<std::int32_t>(d.kind));
    }
  }
}

InterfaceMesh read_mesh(MessageReader& in) {
  InterfaceMesh m;
  const std::string name = in.get_string();
  Eigen::MatrixXd points;
  in.read(points);
  std::vector<int> tri;
  in.read(tri);
  if (points.cols() != 3 || tri.size() % 3 != 0) in.fail("a mesh (points x 3, triangles x 3)");
  Mesh::Triangles t(static_cast<Eigen::Index>(tri.size() / 3), 3);
  std::copy(tri.begin(), tri.end(), t.data());
  m.mesh = Mesh(name, points, t);
  Eigen::VectorXd weights;
  in.read(weights);
  if (weights.size() > 0) m.mesh.set_weights(weights);
  m.prescribed = in.get<std::uint8_t>() != 0;
  for (auto* specs : {&m.reads, &m.writes}) {
    const auto n = in.get<std::uint64_t>();
    for (std::uint64_t i = 0; i < n; ++i) {
      DataSpec d;
      d.name = in.get_string();
      d.components = in.get<std::int32_t>();
      d.unit = in.get_string();
      d.kind = static_cast<DataKind>(in.get<std::int32_t>());
      specs->push_back(d);
    }
  }
  return m;
}

void write_monitors(MessageWriter& out, const std::vector<MonitorValue>& v) {
  out.write(static_cast<std::uint64_t>(v.size()));
  for (const auto& m : v) {
    out.write(m.name);
    out.write(m.unit);
    out.write(m.value);
  }
}

void read_monitors(MessageReader& in, std::vector<MonitorValue>& v) {
  // an item: two counts and a value
  v.resize(in.count(3 * sizeof(std::uint64_t), "a list of monitor values"));
  for (auto& m : v) {
    in.read(m.name);
    in.read(m.unit);
    in.read(m.value);
  }
}

void write_strings(MessageWriter& out, const std::vector<std::string>& v) {
  out.write(static_cast<std::uint64_t>(v.size()));
  for (const auto& s : v) out.write(s);
}

void write_outputs(MessageWriter& out, std::span<const WindowOutput> outputs) {
  out.write(static_cast<std::uint64_t>(outputs.size()));
  for (const WindowOutput& o : outputs) {
    out.write(*o.mesh);
    out.write(*o.data);
    out.write(static_cast<std::uint8_t>(o.combines == WriterCombines::average));
    out.write(static_cast<std::int64_t>(o.points));
    out.write(static_cast<std::int32_t>(o.components));
    out.write(*o.label);
  }
}


void read_strings(MessageReader& in, std::vector<std::string>& v) {
  v.resize(in.count(sizeof(std::uint64_t), "a list of texts"));
  for (auto& s : v) in.read(s);
}

void OutputSlots::read(MessageReader& in) {
  const std::size_t n = in.count(3 * sizeof(std::uint64_t), "a list of outputs");
  names.resize(3 * n);
  combined.resize(n);
  outputs.assign(n, {});
  for (std::size_t i = 0; i < n; ++i) {
    WindowOutput& o = outputs[i];
    in.read(names[3 * i]);
    in.read(names[3 * i + 1]);
    o.combines = in.get<std::uint8_t>() ? WriterCombines::average : WriterCombines::last;
    o.points = in.get<std::int64_t>();
    o.components = in.get<std::int32_t>();
    in.read(names[3 * i + 2]);
  }
  for (std::size_t i = 0; i < n; ++i) {  // (names is sized: the pointers stay valid)
    outputs[i].mesh = &names[3 * i];
    outputs[i].data = &names[3 * i + 1];
    outputs[i].label = &names[3 * i + 2];
    outputs[i].combined = &combined[i];
  }
}

}  // namespace partita::run::remote
