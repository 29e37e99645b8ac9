"""Arm-to-arm transfer, the project's main job. With no arguments it runs the default demo:

a planar 2-joint arm moving its joints (its tip moves in arcs) solves Table I task 1 and hands
its trajectory to a UR5e-like arm moving its tip in Cartesian steps, which learns with no
transfer, with the paper's pseudo reward, and with the dense potential (10 trials each, plus
the controls), and writes runs/<timestamp>/: results.json, table.md, learning_curves.png,
map.png and rollout.mp4 (both arms replayed in MuJoCo physics, rendered offscreen).

    python scripts/transfer_arms.py                 # the default demo
    python scripts/transfer_arms.py --fast          # a quick smoke run
    python scripts/transfer_arms.py --source planar3:joint --target panda_like:cartesian --task 3

Every option of `armtransfer arms` works here (see --help). The video needs offscreen OpenGL
(EGL or OSMesa, see docs/setup.md); where neither works the script says what to install
before it learns anything, and --no-video runs everything but the video.
"""

import sys

from armtransfer import script
from armtransfer.cli import main

if __name__ == "__main__":
    script.exit_with(lambda: main(["arms", *sys.argv[1:]]))
