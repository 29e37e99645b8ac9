"""Every base pose the automatic mount tries for an arm file, with its reach.

The automatic mount (``armtransfer.tasks.arms.automatic_mount``) ranks its candidates by a
quick IK estimate and compiles only the winner (the next only when a compile fails). This
script shows all of them: the estimate for each, then a full compile of the first poses of
``compile_order`` (the best ``COMPILES`` by Table I cells reached then the estimate, then
up to as many more whose estimate beats one of those; ``--compile`` keeps the first N),
with the share of free cells reached and the Table I tasks solvable. Use it to see why a
mount was chosen, or to pick one by hand for ``--base-pos``/``--base-yaw``.

    python research/mount_candidates.py PATH.xml --tip-body Fixed_Jaw --tip-offset=-0.015,-0.13,0
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from armtransfer import script
from armtransfer.ik.tool import parse_offset
from armtransfer.tasks.arms import arm_robot, compile_order, make_tool, mount_search, tasks_solvable
from armtransfer.tasks.catalog import TABLE_I


def main(argv: list[str] | None = None) -> int:
    p = script.parser(__doc__)
    p.add_argument("xml", help="the arm's MJCF file")
    p.add_argument("--tip-site", default=None)
    p.add_argument("--tip-body", default=None)
    p.add_argument("--tip-offset", default=None, metavar="X,Y,Z")
    p.add_argument("--compile", type=int, default=6, metavar="N",
                   help="compile at most the first N of the automatic mount's compiles (default 6)")
    args = p.parse_args(argv)
    return script.run(_run, args)


def _run(args: argparse.Namespace) -> int:
    offset = parse_offset(args.tip_offset) if args.tip_offset else None
    tool = make_tool(args.tip_site, args.tip_body, offset)
    path = Path(args.xml)
    t0 = time.perf_counter()
    rows = mount_search(path, tool)
    print(f"{len(rows)} candidates estimated in {time.perf_counter() - t0:.0f} s "
          f"(share of a sparse lattice of free cells; Table I cells reached)")
    for hit, share, pose in rows:
        print(f"  {pose.describe()}: estimate {share:.1%}, Table I cells {hit}")
    order = compile_order(rows)[:args.compile]
    print(f"full compiles of the {len(order)} poses the automatic mount compiles, in its order:")
    for hit, share, pose in order:
        robot = arm_robot(None, "cartesian", xml_path=path, tip_site=tool.site, tip_body=tool.body,
                          tip_offset=tool.offset, base_pos=pose.pos, base_yaw=pose.yaw)
        print(f"  --base-pos={','.join(f'{v:.4g}' for v in pose.pos)} --base-yaw={pose.yaw:.4g}: "
              f"reach {robot.arm.reach:.1%}, Table I solvable {tasks_solvable(robot)}/{len(TABLE_I)}")
    return 0


if __name__ == "__main__":
    script.exit_with(main)
