#!/usr/bin/env python3
"""A model of the DEM's time per step on many machines, from measured compute and exchange costs.

The split bed (solvers/dem: recursive bisection into boxes of equal particle counts, ghosts within
w = 2 R_max + skin of a box, one refresh of the ghosts' values a step, the sizes of every message
sent to every rank first, the rebuild decision as a max over the ranks) stepping N granules on
M machines of C cores, T threads a rank (P = M C / T ranks). Per step:

  compute   N_r (1 + c_g g) / (T r_core f_split)           N_r = N / P owned, g = ghosts / N_r
  halo      80 B a ghost row each way: within a machine at the memory's copy rate, across
            machines (the machine's block surface) at the network's bandwidth
  messages  2 (P - 1) small messages a step (the sizes before each exchange, the max) at one
            latency each, taken one after the other (an upper bound: they are posted together),
            and the ghosts' data to at most 26 neighbours
  waiting   a share of the compute for imbalance and the machine's jitter

Every input is an option with its default taken from a measurement (bench/README.md names the
run) or, for what no machine here has (a network between machines), a stated assumption. Nothing
here runs the DEM: this is a model, to be read as one; `--help` lists the inputs.

usage: model_ranks.py [--granules N] [--machines M] [--cores C] [--threads 1,4,16] [...]
"""
import argparse
import math


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--granules", type=float, default=1e8, help="N (default 1e8)")
    ap.add_argument("--machines", type=int, default=8, help="M (default 8)")
    ap.add_argument("--cores", type=int, default=16, help="C, cores a machine (default 16)")
    ap.add_argument("--threads", default="1,4,16", help="T values, threads a rank (default 1,4,16)")
    # the bed: the seeds' granules (4, 3.125, 2.5 mm in equal counts) settled at porosity 0.42
    ap.add_argument("--diameters", default="4.0,3.125,2.5", help="granule diameters [mm], equal counts")
    ap.add_argument("--porosity", type=float, default=0.42, help="the bed's porosity (the seeds' section)")
    ap.add_argument("--skin", type=float, default=0.2, help="Verlet skin [mm] (10 %% of R_max)")
    # measured compute
    ap.add_argument("--rate", type=float, default=4.5e6,
                    help="particle-steps/s of one core with every core of the machine busy on a "
                         "settled bed (lent 16-core machine: the large peer bed on 16 threads, "
                         "7.25e7 / 16; the 10^6 scale bed's granules 6.7e6 a core on 16 threads)")
    ap.add_argument("--split", type=float, default=0.88,
                    help="the split path's rate against the fused step of one process (2-core VM, "
                         "peer bed: one rank on 2 threads against one process, 0.88x)")
    ap.add_argument("--ghost-cost", type=float, default=0.5,
                    help="the work of a ghost against an owned particle (its pairs with owned "
                         "particles are computed on both sides; no ghost-ghost pairs): 0.5 an upper "
                         "bound; the VM's 2 ranks at 14 %% ghosts cost 2 %% (0.17)")
    ap.add_argument("--waiting", type=float, default=0.06,
                    help="waiting for the slowest rank, a share of the compute (perf of a rank "
                         "of 2 on the VM: 6 %%)")
    # measured exchange costs (one machine) and the assumed network
    ap.add_argument("--latency-us", type=float, default=1.5,
                    help="one small message within a machine [us] (mpi_pingpong on the VM: 3.0 us "
                         "an 8-byte round trip)")
    ap.add_argument("--copy-gbs", type=float, default=8.0,
                    help="GB/s one rank's halo moves within a machine (a copy: half of one core's "
                         "16 GB/s stream on the VM)")
    ap.add_argument("--net-latency-us", type=float, default=2.0,
                    help="one message between machines [us] (assumed: an InfiniBand EDR/HDR fabric)")
    ap.add_argument("--net-gbs", type=float, default=12.5,
                    help="a machine's network bandwidth [GB/s] (assumed: 100 Gb/s)")
    ap.add_argument("--step", type=float, default=1.906e-6,
                    help="DEM step [s] for the time of an impact (0.2 of the Rayleigh step of a "
                         "2.5 mm granule)")
    ap.add_argument("--impact", type=float, default=0.065,
                    help="simulated time [s] (the seeds' section: 0.065 s to 118 mm)")
    a = ap.parse_args()

    d = [float(x) for x in a.diameters.split(",")]
    v_mean = sum(math.pi / 6 * x ** 3 for x in d) / len(d)  # mm^3
    n = (1 - a.porosity) / v_mean  # granules a mm^3
    w = max(d) + a.skin  # 2 R_max + skin [mm]
    print(f"# model: {a.granules:.3g} granules (diameters {a.diameters} mm, porosity {a.porosity}: "
          f"{n * 1e9:.3g} a m^3, a cube of {(a.granules / n) ** (1 / 3) / 1e3:.2f} m), "
          f"{a.machines} machines x {a.cores} cores; ghost layer {w:.1f} mm")
    print(f"# inputs: {a.rate:.3g} particle-steps/s a core (machine full), split path {a.split}, "
          f"ghost cost {a.ghost_cost}, waiting {a.waiting:.0%}, {a.latency_us} us / "
          f"{a.copy_gbs} GB/s within a machine, {a.net_latency_us} us / {a.net_gbs} GB/s between "
          f"machines (assumed)")
    print(f"{'ranks x T':>10} {'N_r':>9} {'box_mm':>7} {'ghosts':>7} {'compute':>9} "
          f"{'halo':>7} {'network':>8} {'messages':>9} {'waiting':>8} {'step_ms':>8} "
          f"{'psteps/s':>9} {'eff':>5} {'impact_h':>9}")
    cores = a.machines * a.cores
    for t in [int(x) for x in a.threads.split(",")]:
        if t < 1 or a.cores % t:
            raise SystemExit(f"model_ranks: {t} threads do not divide {a.cores} cores")
        p = cores // t
        n_r = a.granules / p
        box = (n_r / n) ** (1 / 3)  # mm, a cube's side
        # an inner box: the upper bound (one rank has none)
        ghosts = n * ((box + 2 * w) ** 3 - box ** 3) if p > 1 else 0.0
        g = ghosts / n_r
        # (one process takes the fused step, its threads' waiting is in --rate)
        compute = n_r * (1 + a.ghost_cost * g) / (t * a.rate * (a.split if p > 1 else 1.0))
        halo = 2 * 80 * ghosts / (a.copy_gbs * 1e9)  # pack + unpack of the rows, a rank
        # a machine's ranks as one block of cores/t boxes (as cubic as the count allows): the rows
        # that cross its surface go over the network, all ranks of a machine sharing its link
        per_machine = a.cores // t
        bx = round(per_machine ** (1 / 3))
        while per_machine % bx:
            bx -= 1
        rest = per_machine // bx
        by = round(math.sqrt(rest))
        while rest % by:
            by -= 1
        bz = rest // by
        sides = (bx * box, by * box, bz * box)
        block_surface = 2 * (sides[0] * sides[1] + sides[1] * sides[2] + sides[0] * sides[2])
        net_rows = n * block_surface * w  # (the outer faces of the bed counted too: a bound)
        network = 80 * net_rows / (a.net_gbs * 1e9) if a.machines > 1 else 0.0
        messages = (2 * (p - 1) * a.latency_us + min(26, p - 1) *
                    (a.net_latency_us if a.machines > 1 else a.latency_us)) * 1e-6
        waiting = a.waiting * compute if p > 1 else 0.0
        step = compute + halo + network + messages + waiting
        ideal = a.granules / (cores * a.rate)
        print(f"{p:>6} x {t:<2} {n_r:>9.3g} {box:>7.0f} {g:>7.1%} {compute * 1e3:>9.1f} "
              f"{halo * 1e3:>7.2f} {network * 1e3:>8.2f} {messages * 1e3:>9.2f} "
              f"{waiting * 1e3:>8.1f} {step * 1e3:>8.1f} {a.granules / step:>9.3g} "
              f"{ideal / step:>5.0%} {a.impact / a.step * step / 3600:>9.2f}")
    print("# eff: against every core at the rate of --rate on the whole bed with no split; "
          "impact_h: hours for --impact at --step (no fragments: they shorten the step)")


if __name__ == "__main__":
    main()
