// The interface-work audit of one coupling mesh (interface_work.hpp).

#include "partita/interface/interface_work.hpp"

#include "partita/interface/state_archive.hpp"

namespace partita {

InterfaceWork InterfaceWork::motion(const Eigen::MatrixX3d& x, const Eigen::MatrixX3d& f) {
  InterfaceWork w(Kind::motion);
  w.now_.a = x;
  w.now_.b = f;
  return w;
}

InterfaceWork InterfaceWork::loads() { return InterfaceWork(Kind::loads); }

void InterfaceWork::motion_step(const Eigen::MatrixX3d& x, const Eigen::MatrixX3d& f) {
  double w = 0.0;
  for (Eigen::Index v = 0; v < f.rows(); ++v)
    w += (now_.b.row(v) + f.row(v)).dot(x.row(v) - now_.a.row(v));
  now_.work -= 0.5 * w;  // f is the bodies' force on the mesh: the mesh's on them is -f
  now_.a = x;            // (no allocation: same sizes)
  now_.b = f;
}

void InterfaceWork::add_nodal_work(double& w, const Eigen::VectorXd& du,
                                   const std::vector<std::size_t>& nodes,
                                   const Eigen::MatrixX3d& forces) {
  const bool previous = now_.a.rows() == forces.rows();
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    const auto r = static_cast<Eigen::Index>(k);
    const auto d = du.segment<3>(3 * static_cast<Eigen::Index>(nodes[k]));
    w += forces.row(r).dot(d);
    if (previous) w += now_.a.row(r).dot(d);
  }
  now_.a = forces;
}

void InterfaceWork::save(BinaryWriter& out) const {
  StateArchive ar(out);
  const_cast<InterfaceWork*>(this)->serialize(ar, {});  // writing leaves the state as it is
}

void InterfaceWork::load(BinaryReader& in, const std::string& what) {
  StateArchive ar(in);
  serialize(ar, what);
}

void InterfaceWork::serialize(StateArchive& ar, const std::string& what) {
  ar.io(now_.work);
  const Eigen::Index rows = now_.a.rows();
  ar.io(now_.a);
  ar.io(now_.b);
  if (ar.reading() && kind_ == Kind::motion && (now_.a.rows() != rows || now_.b.rows() != rows))
    ar.fail(std::to_string(rows) + " " + what);
}

}  // namespace partita
