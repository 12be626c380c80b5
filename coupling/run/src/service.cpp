#include "partita/run/service.hpp"

#include "partita/interface/error.hpp"

namespace partita::run {

void Service::without_section(const std::string& file) {
  throw Error(file + " has no section '" + section() +
              "': it was written by a run without that part; resume with the case it was "
              "written with");
}

}  // namespace partita::run
