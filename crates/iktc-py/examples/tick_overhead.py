"""The Python cost of one imitation tick, to compare with the Rust bench of the same tick.

    python crates/iktc-py/examples/tick_overhead.py
    cargo bench -p iktc --bench humanoid_tick -- humanoid_tick/iktc

Both run JVRC-1 imitating humanoid3d_dance_b (Table 1 stack, IKTC, quiet bounds, level hold 3, continuity 0.3, L_KNEE and
L_HIP_R narrowed, Δt = 5 ms): the bench times `tick` + `integrate` in Rust, this script times
`Imitation.tick()` (the same two calls plus the Python call, the GIL release and the report
turned into Python objects) with timeit, over passes of the whole clip.
"""
import statistics
import time
import timeit

import iktc


def main() -> None:
    sim = iktc.Imitation(iktc.Robot("jvrc1"), iktc.load_motion("humanoid3d_dance_b"))
    n = sim.ticks

    def one_pass():
        sim.reset()
        for _ in range(n):
            sim.tick()

    one_pass()  # warm up
    passes = 5
    best = min(timeit.repeat(one_pass, number=1, repeat=passes))
    reset = min(timeit.repeat(sim.reset, number=1, repeat=passes))
    print(f"Imitation.tick from Python: {(best - reset) / n * 1e6:.1f} µs per tick "
          f"(best of {passes} passes of {n} ticks, reset excluded)")
    # Single ticks, as the bench prints them: median over 5 passes.
    ticks = []
    for _ in range(passes):
        sim.reset()
        for _ in range(n):
            t0 = time.perf_counter()
            sim.tick()
            ticks.append(time.perf_counter() - t0)
    print(f"Imitation.tick from Python: single ticks over {passes} passes of {n}: median "
          f"{statistics.median(ticks) * 1e6:.1f} µs")


if __name__ == "__main__":
    main()
