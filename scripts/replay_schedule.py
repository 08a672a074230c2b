"""Replay a finished sweep's measured case wall times through two local schedules.

Usage: python scripts/replay_schedule.py DIR [--positions K] [--threads 2]

Reads ``wall_s`` of the cases at positions 0..K-1 of sweep DIR (``io.case_order``) and
prints the wall time each schedule would have taken on ``--threads`` cores:

* units: the earlier local scheduler, units of ``--threads`` consecutive positions, each
  unit as long as its slowest case;
* queue: the work queue (``sweeps.local.run_local``), each position in order to the first
  free worker;
* ideal: the sum over the cores.

The first case's wall time includes the first compilation on a fresh install; it is
replaced by the median of the cases that took under 1 s (``--keep-first`` keeps it).
A case started beside it waited for that compilation too and is kept as measured (in
both schedules it runs first).  An estimate from measured times, not a measurement of a
schedule.
"""
import argparse
import heapq

import numpy as np

import loopsim
from loopsim import io


def replay(walls, threads):
    units = sum(max(walls[i:i + threads]) for i in range(0, len(walls), threads))
    free = [0.0] * threads
    for wall in walls:
        heapq.heappush(free, heapq.heappop(free) + wall)
    return units, max(free), sum(walls) / threads


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("directory")
    parser.add_argument("--positions", type=int, default=None)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--keep-first", action="store_true",
                        help="keep the first case's wall time (it may include compilation)")
    args = parser.parse_args()
    frame = loopsim.read_results(args.directory).set_index("case_id")
    order = io.case_order(len(frame.attrs["loopsim"]["sweep_config"]["cases"]))
    count = args.positions or len(order)
    missing = [p for p in range(count) if order[p] not in frame.index]
    if missing:
        raise SystemExit(f"positions not finished yet: {missing[:10]}...; pass a smaller "
                         "--positions")
    walls = [float(frame.loc[order[p], "wall_s"]) for p in range(count)]
    if not args.keep_first:
        walls[0] = float(np.median([w for w in walls if w < 1.0]))
    units, queue, ideal = replay(walls, args.threads)
    print(f"{count} positions on {args.threads} threads: units {units:.0f} s, queue "
          f"{queue:.0f} s, ideal {ideal:.0f} s (units / queue = {units / queue:.2f})")


if __name__ == "__main__":
    main()
