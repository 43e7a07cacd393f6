"""Fig. 2 of the paper from Python: the DLS indicators of the gait against the viscosity c.

    python examples/fig2.py [--points 300] [--out fig2.png]

The same sweep as `vrw sweep` (c from 1 to 300 N s/m, the paper's Table 1), drawn with matplotlib.
"""

import argparse
import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import vrw  # noqa: E402

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("--points", type=int, default=300)
parser.add_argument("--out", default="fig2.png")
args = parser.parse_args()

result = vrw.sweep(vrw.Params(), "viscosity", vrw.linspace(1, 300, args.points))
s = result["sweep"]
c = s["viscosity"]

fig, (a, b) = plt.subplots(2, 1, sharex=True, figsize=(6, 6))
a.plot(c, s["lambda_I4"], "k.-", label=r"$\lambda_{I4}$")
b.plot(c, s["lambda_2_plus"], "b.-", label=r"$\lambda_2^+$")
b.plot(c, s["lambda_4_plus"], "r.-", label=r"$\lambda_4^+$")
for t in result["thresholds"]:
    if t["value"] is not None and math.isfinite(t["value"]):
        for axis in (a, b):
            axis.axvline(t["value"], color="grey", linestyle="--", linewidth=0.8)
a.set_ylabel("impulse [N s]")
b.set_ylabel("force [N]")
b.set_xlabel("viscosity c [N s/m]")
for axis in (a, b):
    axis.axhline(0, color="black", linewidth=0.5)
    axis.legend()
fig.suptitle(f"Fig. 2: DLS indicators of the gait ({result['gaits_found']} gaits)")
fig.savefig(args.out, dpi=120)
print(f"wrote {args.out}")
