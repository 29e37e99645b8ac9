"""Write the MJCF of the project's arms (src/armtransfer/models/<arm>/<arm>.xml) from their dimensions.

The XML files are committed and are what everything loads; this script documents how they
were derived (planar link lengths, and the published Denavit-Hartenberg tables of the
UR5e and the Franka Panda turned into MuJoCo body frames) and rewrites them:

    python scripts/make_arm_models.py

Standard DH (UR5e): T_i = Rz(q_i) Tz(d_i) Tx(a_i) Rx(alpha_i), so the child body sits at
pos (a_i, 0, d_i) with orientation Rx(alpha_i) and rotates about its own z.
Modified DH (Panda): T_i = Rx(alpha_{i-1}) Tx(a_{i-1}) Rz(q_i) Tz(d_i), so body i sits at
(a_{i-1}, 0, 0) + Rx(alpha_{i-1}) (0, 0, d_i) with orientation Rx(alpha_{i-1}).
"""

from __future__ import annotations

from pathlib import Path

from armtransfer import script
from armtransfer.models.mjcf import BUILT_IN

MODELS = Path(__file__).resolve().parents[1] / "src" / "armtransfer" / "models"


def main() -> None:
    for name, build in BUILT_IN.items():
        folder = MODELS / name
        folder.mkdir(parents=True, exist_ok=True)
        (folder / f"{name}.xml").write_text(build())
        print(f"wrote {folder / (name + '.xml')}")


if __name__ == "__main__":
    script.exit_with(main)
