#!/usr/bin/python3
"""Byte identity of the shipped cases' results across a change of the code.

Runs the shortened run of every shipped case (each run listed in a cases/*/checks.yaml, the four
elastic-tube schemes, the scale case on a small box) with a given partita executable, and takes
the SHA-256 of every CSV the run writes. Columns that time the program itself (wall-clock
seconds) differ between two runs of the same binary and are left out of the hash; every other
byte counts.

  identity.py record PARTITA OUT.txt     run everything, write 'run/file hash' lines
  identity.py compare PARTITA REF.txt    run everything, compare with REF.txt, exit 1 on a change

A restructuring that changes no result leaves every line of REF.txt as it is.
"""
import hashlib
import os
import shlex
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
CASES = ROOT / "cases"

# Columns measuring the program rather than the model (seconds of wall time, rates).
TIMING_WORDS = ("wall", "elapsed", "cpu_s", "seconds_per", "per_second", "time_per")


def runs():
    """(name, case file, extra arguments) of every shortened shipped run."""
    out = []
    for checks in sorted(CASES.glob("*/checks.yaml")):
        doc = yaml.safe_load(checks.read_text())
        for run in doc.get("runs", []):
            args = ["--threads", str(run.get("threads", 1))]
            if not run.get("sweep", False):
                args.append("--no-sweep")
            for s in run.get("set", []):
                args += ["--set", s]
            out.append((f"{checks.parent.name}/{run['name']}", checks.parent / run["case"], args))
    for case in sorted((CASES / "elastic_tube_1d").glob("*.yaml")):
        out.append((f"elastic_tube_1d/{case.stem}", case, ["--threads", "1", "--no-sweep"]))
    out.append(("scale/small", CASES / "scale" / "scale.yaml",
                ["--threads", "1", "--no-sweep",
                 "--set", "participants.granules.particles.generate.box.size=[0.05, 0.05, 0.05]",
                 "--set", "time.end=5.0e-5"]))
    return out


def csv_hash(path):
    lines = path.read_text().splitlines()
    if not lines:
        return hashlib.sha256(b"").hexdigest()
    header = lines[0].split(",")
    drop = {i for i, h in enumerate(header) if any(w in h.lower() for w in TIMING_WORDS)}
    h = hashlib.sha256()
    for line in lines:
        cells = line.split(",")
        h.update(",".join(c for i, c in enumerate(cells) if i not in drop).encode())
        h.update(b"\n")
    return h.hexdigest()


def run_all(partita):
    result = {}
    # Threads that sleep at OpenMP's barriers instead of spinning: the bits are the same, and a
    # check run beside other work (a long case, a compiler) is not slowed 3-5 times by spinning.
    env = dict(os.environ)
    env.setdefault("OMP_WAIT_POLICY", "passive")
    with tempfile.TemporaryDirectory(prefix="partita_identity_") as tmp:
        for name, case, args in runs():
            out = Path(tmp) / name.replace("/", "__")
            cmd = [partita, "run", str(case), "--output", str(out), "--log-level", "warn"] + args
            print(f"  {name}", flush=True)
            r = subprocess.run(cmd, capture_output=True, text=True, env=env)
            if r.returncode != 0:
                result[f"{name}/exit"] = f"status-{r.returncode}"
                print(f"    exit {r.returncode}: {shlex.join(cmd)}\n{r.stderr[-2000:]}", file=sys.stderr)
                continue
            for csv in sorted(out.rglob("*.csv")):
                result[f"{name}/{csv.relative_to(out)}"] = csv_hash(csv)
    return result


def main():
    if len(sys.argv) != 4 or sys.argv[1] not in ("record", "compare"):
        print(__doc__, file=sys.stderr)
        return 2
    mode, partita, ref = sys.argv[1], os.path.abspath(sys.argv[2]), Path(sys.argv[3])
    got = run_all(partita)
    if mode == "record":
        head = f"# {len(got)} CSVs of the shipped cases' short runs; SHA-256 without timing columns\n"
        ref.write_text(head + "".join(f"{k} {v}\n" for k, v in sorted(got.items())))
        print(f"{len(got)} files hashed into {ref}")
        return 0
    want = dict(line.split(" ", 1) for line in ref.read_text().split("\n")
                if line and not line.startswith("#"))
    changed = [k for k in sorted(set(want) | set(got)) if want.get(k) != got.get(k)]
    for k in changed:
        print(f"CHANGED {k}: {want.get(k, 'absent')} -> {got.get(k, 'absent')}")
    print(f"{len(got)} files hashed, {len(changed)} differ from {ref}")
    return 1 if changed else 0


if __name__ == "__main__":
    sys.exit(main())
