// Participants as processes over MPI (distributed.hpp): MPI start-up, the processes' names, the
// channels between the controller and the other processes, and the failure paths; and a case of
// one participant on the ranks of mpirun (run_on_ranks()).
#include "distributed.hpp"

#include <chrono>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <iostream>
#include <thread>

#include <fmt/format.h>

#include "partita/interface/error.hpp"
#include "partita/interface/log.hpp"
#include "partita/interface/participant_ranks.hpp"
#include "partita/run/remote_participant.hpp"

#ifdef PARTITA_MPI
#include "partita/mpi/mpi_channel.hpp"
#endif

namespace partita::app {

bool started_with_others() {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* v = std::getenv(var); v && std::atoi(v) > 1) return true;
  return false;
}

bool started_by_mpirun() {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"})
    if (const char* v = std::getenv(var); v && *v) return true;
  return false;
}

#ifndef PARTITA_MPI

bool distributed_available() {
  return false;
}

int run_on_ranks(const coupling::Registries&, RanksOptions) {
  std::cerr << "partita: error: this process was started by mpirun with others, and this partita "
               "was built without MPI: it cannot run a case on several ranks (install "
               "libopenmpi-dev and openmpi-bin, e.g. ./build.sh deps, and build again)\n";
  return 1;
}

int run_distributed(const coupling::Registries&, DistributedOptions) {
  std::cerr << "partita: error: --participant runs participants as separate processes over MPI, "
               "and this partita was built without MPI (install libopenmpi-dev and openmpi-bin, "
               "e.g. ./build.sh deps, and build again)\n";
  return 1;
}

#else

bool distributed_available() {
  return true;
}

int run_on_ranks(const coupling::Registries& registries, RanksOptions o) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  static MPI_Comm world = MPI_COMM_WORLD;  // (the handle points to it)
  auto ranks = std::make_shared<ParticipantRanks>(rank, size, &world, o.peer_timeout);
  ranks->set_stop_flag(o.stop_signal);
  run::RunOptions& ro = o.run;
  ro.ranks = ranks;
  if (rank != 0) {
    // the others build the case alike and write nothing: rank 0's solver drives theirs; their
    // set-up's log lines would be rank 0's again
    ro.check_only = true;
    ro.check_sweep_values = false;
    if (log::get("app")->level() < spdlog::level::warn) log::set_level(spdlog::level::warn);
  }
  std::unique_ptr<run::CaseRun> c;
  // the solver (its transport) goes before MPI_Finalize; after a failure in the middle of what
  // the ranks do together, every rank ends at once (the others may wait in a collective)
  auto end = [&](int status, bool abort) {
    if (abort) MPI_Abort(MPI_COMM_WORLD, status == 0 ? 1 : status);
    c.reset();
    MPI_Finalize();
    return status;
  };
  auto say = [&](const std::exception& e) {
    const std::string what = dynamic_cast<const Error*>(&e) != nullptr
                                 ? std::string(e.what())
                                 : "internal error: " + std::string(e.what());
    // every rank builds and meets the same errors: rank 0 says them; another rank speaks for a
    // failure of its own (which broke the ranks' work together)
    // (one write: the ranks' lines reach mpirun's output whole)
    if (rank == 0)
      std::cerr << ("partita: error: " + what + "\n") << std::flush;
    else if (ranks->broken())
      std::cerr << fmt::format("partita: error: rank {} of {}: {}\n", rank, size, what)
                << std::flush;
  };
  try {
    c = std::make_unique<run::CaseRun>(o.case_file, registries, ro);
  } catch (const std::exception& e) {
    say(e);
    return end(1, ranks->broken());
  }
  if (!ranks->claimed() && size > 1) {
    if (rank == 0)
      std::cerr << fmt::format(
          "partita: error: {}: its participant's solver does not run on several ranks (mpirun "
          "-n {}); run the case in one process, without mpirun (a DEM participant runs on "
          "several ranks)\n",
          o.case_file.string(), size);
    return end(1, false);
  }
  if (o.install_stop_handlers) o.install_stop_handlers();
  int status = 0;
  try {
    if (rank == 0) {
      c->run();
      if (const int signal = c->summary().stopped_by_signal; signal != 0) {
        std::cout << "partita run: stopped by signal " << signal << " after window "
                  << c->summary().windows << "; output in " << c->output_dir().string() << "/";
        if (!c->summary().last_restart.empty())
          std::cout << "; continue with: mpirun -n " << size << " partita run "
                    << o.case_file.string() << " --resume " << c->output_dir().string();
        std::cout << "\n";
        status = 128 + signal;
      }
      ranks->end(status);  // (the solver's finalize() ended the others' loops already)
      if (status == 0 && o.on_finished) o.on_finished(*c);
    } else {
      status = ranks->follow();
    }
  } catch (const std::exception& e) {
    if (rank == 0 && !ranks->broken()) {
      try {
        ranks->end(1);
      } catch (...) {
        ranks->set_broken();
      }
    }
    say(e);
    return end(1, ranks->broken());
  }
  return end(status, false);
}

// A process of a participant on several ranks other than its leader: builds that participant
// alone (check-only: it writes nothing) and follows its leader until the leader's solver ends the
// run. A failure of its own in the middle of the ranks' work together ends every process
// (MPI_Abort) after its message; anything else is said by the leader or the controller.
static int follow_leader(const coupling::Registries& registries, DistributedOptions& o,
                         const mpi::Membership& m, const std::shared_ptr<ParticipantRanks>& ranks) {
  run::RunOptions& ro = o.run;
  ro.check_only = true;
  ro.check_sweep_values = false;
  ro.ranks = ranks;
  if (log::get("app")->level() < spdlog::level::warn) log::set_level(spdlog::level::warn);
  const std::string who = fmt::format("participant '{}' rank {} of {} (rank {} of the run)",
                                      o.participant, m.local_rank, m.local_size, m.rank);
  std::unique_ptr<run::CaseRun> c;
  int status = 1;
  try {
    c = std::make_unique<run::CaseRun>(o.case_file, registries, ro);
    if (o.install_stop_handlers) o.install_stop_handlers();
    status = ranks->follow();
  } catch (const std::exception& e) {
    // the same set-up error as the leader's, which says it: only a failure of this rank's own
    // while the ranks work together is said here (the leader may wait in vain)
    if (ranks->broken()) {
      const std::string what = dynamic_cast<const Error*>(&e) != nullptr
                                   ? std::string(e.what())
                                   : "internal error: " + std::string(e.what());
      const std::string note = ranks->world_note();
      std::cerr << ("partita: error: " + who + ": " + what +
                    (what.find(note) == std::string::npos ? note : std::string()) + "\n")
                << std::flush;
      MPI_Abort(MPI_COMM_WORLD, 1);
    }
    status = 1;
  }
  c.reset();  // (the solver's transport before MPI_Finalize)
  return status;
}

int run_distributed(const coupling::Registries& registries, DistributedOptions o) {
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  int rank = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  auto fail = [&](const std::string& what, bool stuck) {
    std::cerr << ("partita: error: " + what + "\n") << std::flush;
    if (stuck) MPI_Abort(MPI_COMM_WORLD, 1);  // a stuck peer would hold MPI_Finalize forever
    MPI_Finalize();
    return 1;
  };

  // Who runs what: one process per participant, or several for a participant whose solver runs
  // on ranks (its first process leads them; the controller and the others talk to the leader).
  mpi::Membership m;
  try {
    m = mpi::join(MPI_COMM_WORLD, o.participant, /*several=*/true);
  } catch (const Error& e) {
    if (rank == 0) return fail(e.what(), false);  // (every process meets it alike: one says it)
    MPI_Finalize();
    return 1;
  }
  const std::vector<std::string>& names = m.participants;
  static MPI_Comm participant_comm = MPI_COMM_NULL;  // (ParticipantRanks points to it)
  participant_comm = m.participant_comm;
  std::shared_ptr<ParticipantRanks> ranks;
  if (m.local_size > 1 || o.on_ranks) {
    // a rank's wait for another is half the controller's for a participant (--peer-timeout), so
    // that a stalled rank is named by its leader before the controller gives up on the leader
    ranks = std::make_shared<ParticipantRanks>(m.local_rank, m.local_size, &participant_comm,
                                               0.5 * o.peer_timeout);
    ranks->set_world_ranks(m.world_ranks);
    ranks->set_stop_flag(o.stop_signal);
  }
  run::RunOptions& ro = o.run;
  ro.distributed.participant = o.participant;
  if (ranks && !ranks->leads()) {
    const int status = follow_leader(registries, o, m, ranks);
    MPI_Comm_free(&participant_comm);
    MPI_Finalize();
    return status;
  }
  ro.ranks = ranks;

  std::vector<std::unique_ptr<mpi::MpiChannel> > channels;
  if (rank == 0) {
    for (int r = 1; r < m.size; ++r) {
      if (!m.leads_other(r)) continue;  // (a follower of its participant's leader)
      channels.push_back(std::make_unique<mpi::MpiChannel>(
          MPI_COMM_WORLD, r, fmt::format("participant '{}' (rank {})", names[r], r),
          o.peer_timeout));
      ro.distributed.servers.emplace_back(names[r], channels.back().get());
    }
  } else {
    channels.push_back(std::make_unique<mpi::MpiChannel>(
        MPI_COMM_WORLD, 0, fmt::format("the controller, participant '{}' (rank 0)", names[0]),
        o.peer_timeout));
    ro.distributed.controller = channels.back().get();
  }
  const std::string who = fmt::format("participant '{}' (rank {})", o.participant, rank);
  int status = 0;
  bool built = false;
  std::unique_ptr<run::CaseRun> c;
  // a participant on ranks: its other ranks end with this one (end(): the status; nothing where
  // its solver has ended them); true when they cannot be told (MPI_Abort then)
  auto end_ranks = [&](int with) {
    if (!ranks || ranks->broken()) return ranks != nullptr;
    try {
      ranks->end(with);
    } catch (...) {
      ranks->set_broken();
    }
    return ranks->broken();
  };
  try {
    c = std::make_unique<run::CaseRun>(o.case_file, registries, ro);
    built = true;
    if (o.install_stop_handlers) o.install_stop_handlers();
    c->run();
    if (const int signal = c->summary().stopped_by_signal; signal != 0) {
      std::cout << "partita run: " << who << " stopped by signal " << signal;
      if (rank == 0) std::cout << " after window " << c->summary().windows;
      std::cout << "\n";
      status = 128 + signal;
    }
    end_ranks(status);
    if (status == 0 && rank == 0) {
      if (o.on_finished) o.on_finished(*c);
    } else if (status == 0) {
      std::cout << "partita run: " << who << " finished\n";
    }
  } catch (const std::exception& e) {
    bool stuck = dynamic_cast<const mpi::PeerTimeout*>(&e) != nullptr;
    const std::string what = dynamic_cast<const Error*>(&e)
                                 ? std::string(e.what())
                                 : "internal error: " + std::string(e.what());
    std::string note = ranks ? ranks->world_note() : std::string();
    if (!note.empty() && what.find(note) != std::string::npos) note.clear();  // (said)
    bool said = false;
    if (rank == 0) {
      // said before the others hear of it (one of them may end every process at once)
      std::cerr << ("partita: error: " + who + ": " + what + note + "\n") << std::flush;
      said = true;
      for (auto& ch : channels) run::abort_server(*ch, who + " stopped the run: " + what);
    } else if (!built && !stuck && dynamic_cast<const run::StoppedByController*>(&e) == nullptr) {
      // the controller waits for this process's hello or final meshes: tell it, and wait for its
      // answer so that it can name this failure before every process ends
      run::ParticipantServer(*channels.front()).fail_setup(what);
      try {
        channels.front()->receive("the controller's answer to this failure");
      } catch (...) {
      }
    }
    // the participant's other ranks: ended with status 1, or (a rank that failed or stopped
    // answering in the middle of their work together) with every process; so too where the
    // set-up failed after the solver claimed the ranks (the others follow a solver that is gone)
    stuck = end_ranks(1) || stuck;
    if (!built && ranks && ranks->size() > 1 && ranks->claimed()) stuck = true;
    for (auto& ch : channels) ch->drain(2.0);
    channels.clear();
    if (!said) std::cerr << ("partita: error: " + who + ": " + what + note + "\n") << std::flush;
    if (stuck) MPI_Abort(MPI_COMM_WORLD, 1);
    c.reset();
    MPI_Comm_free(&participant_comm);
    MPI_Finalize();
    return 1;
  }
  channels.clear();
  c.reset();
  MPI_Comm_free(&participant_comm);
  MPI_Finalize();
  return status;
}

#endif

}  // namespace partita::app
