"""The Touch's gimbal through Pinocchio (the `pin` wheel), an FK independent of
tactile-chain: the stylus' orientation in the base frame of deploy/devices/
phantom_omni.urdf at random joint values, as JSON on stdout (tests/chain.rs)."""

import argparse
import json

import numpy as np
import pinocchio as pin


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--urdf", required=True)
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--cases", type=int, default=200)
    a = ap.parse_args()
    model = pin.buildModelFromUrdf(a.urdf)
    data = model.createData()
    names = [model.names[j] for j in range(1, model.njoints)]
    tip = model.getFrameId("stylus")
    rng = np.random.default_rng(a.seed)
    cases = []
    for _ in range(a.cases):
        # Beyond the URDF's limits too: the gimbal reads whatever the driver sends.
        q = rng.uniform(-2.0 * np.pi, 2.0 * np.pi, model.nq)
        pin.framesForwardKinematics(model, data, q)
        m = data.oMf[tip]
        cases.append({"q": q.tolist(), "r": m.rotation.tolist(), "p": m.translation.tolist()})
    json.dump({"joints": names, "cases": cases}, __import__("sys").stdout)


if __name__ == "__main__":
    main()
