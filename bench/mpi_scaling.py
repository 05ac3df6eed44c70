#!/usr/bin/env python3
"""Measures rsibr over MPI ranks on this machine and writes the "MPI scaling" section of
docs/performance.md: strong scaling of one bake (`mpirun -n N rsibr --threads 1 bake`, the same
bytes at every N) and weak scaling of a batch (the same jobs per rank), at 1 and 2 ranks of one
thread each, and a cost model fitted to them that predicts 8, 64 and 512 ranks.

Model of an N-rank bake (seconds), from the bake's JSON (rank 0's view) and the wall clock:
  T(N) = launch(N) + setup + integrate / N + gather(N) + write
  launch(N) = a0 + a1 N          (mpirun starting N processes; fitted from N = 1 and 2)
  gather(N) = B (1 - 1/N) / beta (rank 0 receives every other rank's rows, one link)
setup (each rank reads the environment and builds its sampling tables) and write (rank 0 alone
writes the EXR) do not shrink with N. beta is measured here (shared memory); across machines the
link's bandwidth replaces it (the table assumes 10 Gb/s, 1.25e9 B/s).
Usage: bench/mpi_scaling.py [--rsibr build/release/rsibr] [--env cache/assets/hdri/...]"""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "bench"))
from convert_roundtrip import replace_section  # noqa: E402

ENV = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
LINK = 1.25e9  # bytes/s of a 10 Gb/s network, for ranks on other machines


def run(cmd):
    t0 = time.perf_counter()
    subprocess.run(cmd, check=False, env=ENV, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - t0


def launcher(n):
    # 1 rank through mpirun too, so launch(2) - launch(1) is one more rank, not mpirun's own start.
    return ["mpirun", "-n", str(n), "--oversubscribe"]


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rsibr", default=os.path.join(ROOT, "build/release/rsibr"))
    ap.add_argument("--env", default=os.path.join(ROOT, "cache/assets/hdri/esplanade.exr"))
    ap.add_argument("--views", default="42")
    ap.add_argument("--res", type=int, default=96)
    ap.add_argument("--samples", type=int, default=16)
    ap.add_argument("--jobs-per-rank", type=int, default=4)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs/performance.md"))
    args = ap.parse_args()
    work = tempfile.mkdtemp(prefix="rsibr_mpi_")
    brdf = os.path.join(work, "ggx.yaml")
    with open(brdf, "w") as f:
        f.write("type: ggx\nroughness: 0.2\nfresnel: {type: schlick, f0: [0.9, 0.7, 0.4]}\n")
    bake = ["--env", args.env, "--brdf", brdf, "--views", args.views, "--res", str(args.res), "--method", "mis",
            "--samples", str(args.samples), "--seed", "1", "-q"]

    strong, outputs = {}, {}
    for n in (1, 2):
        out, js = os.path.join(work, f"strong{n}.exr"), os.path.join(work, f"strong{n}.json")
        wall = run(launcher(n) + [args.rsibr, "--threads", "1", "bake", out, "--json", js] + bake)
        strong[n] = dict(json.load(open(js)), wall=wall)
        outputs[n] = open(out, "rb").read()
    same = outputs[1] == outputs[2]
    launch = {n: strong[n]["wall"] - sum(strong[n]["seconds"][k] for k in ("setup", "integrate", "write")) for n in (1, 2)}

    # Weak scaling: jobs_per_rank small bakes per rank.
    weak = {}
    for n in (1, 2):
        spec = os.path.join(work, f"batch{n}.yaml")
        with open(spec, "w") as f:
            f.write("jobs:\n")
            for i in range(n * args.jobs_per_rank):
                f.write(f"  - [bake, weak{n}_{i}.exr, --env, {args.env}, --brdf, {brdf}, --views, icosa, --res, "
                        f"{args.res}, --samples, {args.samples}, --seed, '{i}', -q]\n")
        js = os.path.join(work, f"batch{n}.json")
        wall = run(launcher(n) + [args.rsibr, "--threads", "1", "batch", spec, "--json", js, "-q"])
        weak[n] = dict(json.load(open(js)), wall=wall)

    s1, s2 = strong[1]["seconds"], strong[2]["seconds"]
    integrate = s1["integrate"]
    setup, write = s1["setup"], s1["write"]
    views = strong[1]["views"]
    nbytes = views * args.res * args.res * 12
    beta = nbytes * 0.5 / max(s2["gather"], 1e-6)  # rank 0 received half the rows
    a1 = max(0.0, launch[2] - launch[1])  # starting one more rank cannot save time: noise below 0
    a0 = launch[1] - a1

    def model(n, bw):
        return a0 + a1 * n + setup + integrate / n + nbytes * (1 - 1 / n) / bw + write

    rows = [f"| {n} | {strong[n]['wall']:.2f} s | {strong[n]['seconds']['setup']:.2f} s | "
            f"{strong[n]['seconds']['root_integrate']:.2f} s | {strong[n]['seconds']['gather']:.3f} s | "
            f"{strong[n]['seconds']['write']:.3f} s | {strong[1]['wall'] / strong[n]['wall']:.2f}x |" for n in (1, 2)]
    wrows = [f"| {n} | {n * args.jobs_per_rank} | {weak[n]['wall']:.2f} s | "
             f"{weak[1]['wall'] / weak[n]['wall']:.2f} |" for n in (1, 2)]
    prows = []
    for n in (1, 2, 8, 64, 512):
        t_shm, t_net = model(n, beta), model(n, LINK)
        prows.append(f"| {n} | {t_shm:.2f} s | {t_net:.2f} s | {model(1, LINK) / t_net:.1f}x |")
    big = 642 * 512 * 512 * 12
    load = os.getloadavg()[0]
    body = "\n".join([
        f"`bench/mpi_scaling.py` (this machine: {os.cpu_count()} cores, load {load:.1f}). One rank = one process of "
        "one thread (`rsibr --threads 1`), so 1 and 2 ranks compare like with like. The 2-rank bake's EXR is "
        f"{'byte-identical to' if same else 'DIFFERENT from'} the 1-rank one.",
        "",
        f"Strong scaling: one bake, {views} views x {args.res}^2, GGX 0.2, mis {args.samples} samples "
        f"({nbytes / 1e6:.1f} MB of maps). Times are rank 0's (setup: reading the environment and building its "
        "tables; integrate: its own rows; gather: receiving the others' rows).",
        "",
        "| ranks | wall | setup | rank 0 integrate | gather | write | speed-up |",
        "|---|---|---|---|---|---|---|",
        *rows,
        "",
        f"Weak scaling: `rsibr batch`, {args.jobs_per_rank} bakes per rank (12 views x {args.res}^2 each), job i on "
        "rank i mod N.",
        "",
        "| ranks | jobs | wall | efficiency (T1 / TN) |",
        "|---|---|---|---|",
        *wrows,
        "",
        f"Model (fitted here): launch {a0:.3f} + {a1:.3f} N s, setup {setup:.2f} s, integrate {integrate:.2f} s "
        f"of one thread, write {write:.3f} s, gather bandwidth {beta / 1e9:.2f} GB/s in shared memory "
        f"(model: T(N) = launch + setup + integrate/N + B(1-1/N)/beta + write, B = {nbytes / 1e6:.1f} MB).",
        "",
        "| ranks | predicted (one machine's memory) | predicted (10 Gb/s network) | speed-up (network) |",
        "|---|---|---|---|",
        *prows,
        "",
        "What stops scaling: the parts that do not divide. Every rank reads the environment and builds its "
        "sampling tables (setup), rank 0 alone receives every row (B grows with the job: a 642-view 512^2 set is "
        f"{big / 1e9:.1f} GB, {big / LINK:.1f} s on one 10 Gb/s link) and writes the one EXR, and mpirun's start "
        "grows with N (fitted here, where the extra ranks start on the same two cores: a pessimistic slope). The rows are split by texel count (cluster/bake_partition.h), so ranks stay busy until "
        "there are more ranks than rows; a batch gives job i to rank i mod N, so a batch of unequal jobs waits for "
        "its slowest rank.",
    ])
    replace_section(args.out, "MPI scaling (mpirun rsibr bake, rsibr batch)", body)
    print("mpi_scaling: wrote", args.out, "(same bytes)" if same else "(BYTES DIFFER)")


if __name__ == "__main__":
    main()
