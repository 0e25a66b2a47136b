"""Which task of the whole-body QP plans the ground force a body takes (prints figures; a tool for explaining a
brake or a push the COM task did not ask for).

    python benchmarks/qp_attribution.py 02_01 --seed 0 --follow-path --from 0.50 --to 0.62 [--every 1] [--top 4]

Runs a development-suite clip (or a source spec) as `benchmarks/trace_run.py` does and, on each control tick from
``--from`` to ``--to``, solves the tick's QP again (`WholeBodyController.plan_attribution`, by a solver of its own:
the run itself is the same bit for bit) as it was and with each active task switched off in turn. Columns, world
frame, newtons, horizontal (x, y):

    t            simulated time [s]
    op/ch        the operator's and the character's stance; ``+held`` a late contact holding the reference,
                 ``+own`` a step of the character's own
    asked        the COM task's force (Eq. 16 with the LIPM term, within what the support can give)
    planned      the ground's total force in the QP's solution (the momentum's rate plus the weight)
    -TASK        the same with that task switched off
    posture      the joint posture task's costliest DOFs in the solution: joint[axis] desired/planned [rad/s²]
"""

from __future__ import annotations

import argparse
import dataclasses
import logging

import numpy as np
from trace_run import resolve

from stylesync.config import follow_path
from stylesync.metrics.dev_suite import suite_config
from stylesync.model.character import JOINT_DOF_START, JOINTS
from stylesync.session import Session
from stylesync.sources.registry import open_source


def dof_name(dof: int) -> str:
    """'joint[axis]' of a DOF of the joint layout (the posture task's)."""
    k = max(i for i in range(len(JOINTS)) if JOINT_DOF_START[i] <= dof)
    return f"{JOINTS[k].name}[{dof - JOINT_DOF_START[k]}]"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("clip", help="a development-suite clip name or a source spec")
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--from", dest="t0", type=float, default=0.0, help="first time printed [s]")
    ap.add_argument("--to", dest="t1", type=float, required=True, help="last time printed; the run ends there [s]")
    ap.add_argument("--every", type=int, default=1, help="print every this many control ticks")
    ap.add_argument("--top", type=int, default=3, help="the posture task's costliest DOFs printed")
    ap.add_argument("--follow-path", action="store_true", help="with --follow-path's settings (config.follow_path)")
    args = ap.parse_args()
    logging.disable(logging.WARNING)
    spec = resolve(args.clip)
    opened = open_source(spec, seed=args.seed, duration_s=args.t1 + 1.0)
    cfg, _ = suite_config(spec, opened, args.seed, args.t1 + 1.0)
    if args.follow_path:
        cfg = follow_path(cfg)
    session = Session(dataclasses.replace(cfg, duration_s=args.t1), opened.source)
    if not hasattr(session.controller, "plan_attribution"):
        raise SystemExit("the controller of these settings solves no whole-body QP")
    print(f"{spec}, seed {args.seed}; horizontal forces (x, y) [N]")
    count = {"n": 0}

    def xy(f: np.ndarray) -> str:
        return f"({f[0]:+5.0f},{f[1]:+5.0f})"

    def on_tick(state, ref) -> None:
        if not args.t0 <= state.time_s <= args.t1:
            return
        count["n"] += 1
        if (count["n"] - 1) % args.every:
            return
        motion = session.motion
        flags = ("+own" if motion.char_fsm.recovery_step else "") + ("+held" if motion.reading.held else "")
        plan = session.controller.plan_attribution()
        forces = plan.ground_force_n
        off = " ".join(f"-{name} {xy(f)}" for name, f in forces.items() if name)
        top = np.argsort(plan.posture_cost)[::-1][:args.top]
        posture = " ".join(f"{dof_name(d)} {plan.posture_desired_rad_s2[d]:+.0f}/{plan.posture_planned_rad_s2[d]:+.0f}"
                           for d in top)
        print(f"{state.time_s:6.3f} {motion.reading.operator_stance.name:>2} {ref.character_stance.name + flags:>8} "
              f"asked {xy(session.controller.telemetry.com_force_n)} planned {xy(forces[''])} {off} | "
              f"posture {posture}")

    session.on_tick = on_tick
    try:
        session.run()
    finally:
        opened.source.close()


if __name__ == "__main__":
    main()
