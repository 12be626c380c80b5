"""ctest `python-external` (python/CMakeLists.txt): the 1D tube's wall as an external Python
program (examples/python/tube_external.py, partita.ExternalParticipant) beside partita's fluid
under mpirun, as the C++ program examples/external_tube does in its ctest test.

    external_tube_mpi.py PARTITA MPIRUN WORK_DIR      (PYTHONPATH naming the build's python/)

Asserts:
- the run's coupling.csv and tube.csv are byte for byte those of cases/elastic_tube_1d/iqn-ils.yaml
  run in one process (the in-tree tube1d-solid), which the C++ external program gives too: the
  same iteration counts per window (854 over 100 windows), the same pressures and areas;
- the same through mpi4py's COMM_WORLD (MPI initialised by mpi4py, the communicator passed in);
- the run stopped at t = 0.5 s and resumed from its restart file (the program's area in it, from
  its restart writer) gives the same bytes again, and the same last restart file;
- the program as the first process is refused (partita runs the coupling core).
Not collected by pytest (its name has no test_ prefix); exits 1 with the reason on a failure.
"""
import os
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "examples" / "external_tube" / "tube_external.yaml"
PROGRAM = ROOT / "examples" / "python" / "tube_external.py"
ENV = {**os.environ, "OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
       "PARTITA_LOG_LEVEL": "warn", "PARTITA_NO_PLOTS": "1"}


def fail(why):
    print(f"external_tube_mpi.py: FAILED: {why}", file=sys.stderr)
    sys.exit(1)


def run(cmd, timeout=240):
    done = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, env=ENV,
                          timeout=timeout)
    return done.returncode, done.stdout + done.stderr


def main():
    partita, mpirun, work = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    rc, out = run([partita, "run", ROOT / "cases" / "elastic_tube_1d" / "iqn-ils.yaml", "-o",
                   work / "one", "--threads", "1"])
    if rc:
        fail(f"the tube case in one process: {rc} {out}")
    restart = ["--set", "output.restart.every_windows=10"]

    def with_program(partita_args, program_args, first="partita"):
        side_partita = ["-n", "1", partita, "run", CASE, "--threads", "1", "--participant", "fluid",
                        *partita_args]
        side_program = ["-n", "1", sys.executable, PROGRAM, CASE, *program_args]
        sides = side_partita + [":"] + side_program if first == "partita" else \
            side_program + [":"] + side_partita
        return run([mpirun, "--oversubscribe", *sides])

    def same_as_one_process(folder, what):
        for csv in ("coupling.csv", "tube.csv"):
            a, b = (work / "one" / csv).read_bytes(), (folder / csv).read_bytes()
            if a != b:
                iterations = [line.split(",")[2] for line in (folder / "coupling.csv").read_text().splitlines()[1:]]
                fail(f"{csv} of {what} differs from the in-process tube's (iterations per window: "
                     f"{' '.join(iterations)})")
        print(f"{what}: coupling.csv and tube.csv are byte for byte those of the run in one process")

    rc, out = with_program(["-o", work / "two", *restart], restart)
    if rc or "tube_external.py: finished" not in out:
        fail(f"partita with the Python program: {rc} {out}")
    same_as_one_process(work / "two", "the run with the Python program")

    rc, out = with_program(["-o", work / "mpi4py"], ["--mpi4py"])
    if rc or "tube_external.py: finished" not in out:
        fail(f"partita with the Python program through mpi4py's COMM_WORLD: {rc} {out}")
    same_as_one_process(work / "mpi4py", "the run through mpi4py's communicator")

    half = [*restart, "--set", "time.end=0.5"]
    rc, out = with_program(["-o", work / "four", *half], half)
    if rc or not (work / "four" / "restart" / "w000000000050.bin").exists():
        fail(f"the Python program's run to 0.5 s wrote no restart file at window 50: {rc} {out}")
    rc, out = with_program(["--resume", work / "four", *restart], restart)
    if rc or "tube_external.py: resumed at t = 0.5 s" not in out or "tube_external.py: finished" not in out:
        fail(f"the Python program's run did not resume from t = 0.5 s: {rc} {out}")
    same_as_one_process(work / "four", "the resumed run")
    last = "restart/w000000000100.bin"
    if (work / "two" / last).read_bytes() != (work / "four" / last).read_bytes():
        fail("the last restart file of the resumed run differs from the uninterrupted one's")
    print("resumed at 0.5 s: the last restart file is the uninterrupted run's")

    rc, out = with_program(["-o", work / "three"], [], first="program")
    if rc == 0 or "start partita first" not in out:
        fail(f"the Python program as the first process was not refused: {rc} {out}")
    print("the Python program as the first process is refused")


if __name__ == "__main__":
    main()
