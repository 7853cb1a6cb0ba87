"""What a Python callable in the loop costs, in release (docs/15-python.md):
a trivial operator (a tuple, a NumPy array) against the same constant target built in,
and the built-in linear predictor written with NumPy against the built-in one, on a
lossy run with deadband codecs. Usage, from the repository's root with the package
installed: python3 deploy/python/bench/loop_cost.py [REPEATS]"""
import statistics
import sys
import time

import numpy as np

import tactile

N = 300_000
REPEATS = int(sys.argv[1]) if len(sys.argv) > 1 else 5
base = tactile.Scenario.load("deploy/scenarios/lockstep-1e6.toml").with_set({"samples": N})
P = [0.0, 0.15, 0.05]
toml = base.to_toml()
still = tactile.Scenario.from_toml(toml.replace(
    '[operator]\nkind = "paper"',
    f'[operator]\nkind = "press"\nfrom = {P}\nto = {P}\nmove_s = 1.0'))
lossy = base.with_set({"codec.forward.kind": "deadband", "codec.backward.kind": "deadband",
                       "network.forward.loss": 0.05, "network.backward.loss": 0.05,
                       "slave.predictor.kind": "linear", "master.predictor.kind": "linear"})
here, arr = tuple(P), np.array(P)
calls = [0]


def linear(n, to, h):
    calls[0] += 1
    t1, x1 = h[-1, 0], h[-1, 1:]
    if len(h) < 2 or not to > t1 > h[-2, 0]:
        return x1
    t0, x0 = h[-2, 0], h[-2, 1:]
    return x1 + (to - t1) / (t1 - t0) * (x1 - x0)


cases = {
    "operator built in": (still, {}),
    "operator tuple": (base, {"operator": lambda n, t, f: here}),
    "operator ndarray": (base, {"operator": lambda n, t, f: arr}),
    "predictor built in": (lossy, {}),
    "predictor numpy": (lossy, {"forward_predictor": linear, "backward_predictor": linear}),
}
times = {k: [] for k in cases}
summaries = {}
for _ in range(REPEATS):
    for name, (sc, hooks) in cases.items():
        calls[0] = 0
        t = time.perf_counter()
        r = tactile.run(sc, trace_format=None, **hooks)
        times[name].append(time.perf_counter() - t)
        summaries[name] = (r.summary["tracking_rms_m"], calls[0])
assert len({summaries[k][0] for k in cases if k.startswith("operator")}) == 1
assert summaries["predictor built in"][0] == summaries["predictor numpy"][0]
med = {k: statistics.median(v) for k, v in times.items()}
for k, v in times.items():
    print(f"{k:20s} median {med[k]:.3f} s of {[round(x, 3) for x in v]}")
for k in ["operator tuple", "operator ndarray"]:
    print(f"{k}: {(med[k] - med['operator built in']) / N * 1e6:.2f} us a sample")
n = summaries["predictor numpy"][1]
print(f"predictor numpy: {n} calls a run, "
      f"{(med['predictor numpy'] - med['predictor built in']) / n * 1e6:.2f} us a call")
