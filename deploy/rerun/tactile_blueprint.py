"""Write a Rerun blueprint (.rbl) for a Tactile run.mcap.

The layout has a 3D view of both arms on the left. The arms are the URDF from
/robot_description posed by /tf. The camera looks from the front side at the
whole workspace: world x from -0.35 to 0.35 m and z from 0 to 0.35 m, z up. On
the right are plots of the master's joint positions, the slave's joint
positions and the slave's joint efforts. The side panels start collapsed.

It needs rerun-sdk==0.41.0 (`pip install rerun-sdk==0.41.0`). Other versions
may not read the blueprint.

    python3 tactile_blueprint.py tactile.rbl
    rerun mcap convert run.mcap --application-id run -o run.rrd
    rerun rrd merge run.rrd tactile.rbl > merged.rrd
    rerun merged.rrd

A blueprint applies only to recordings with the same application id, so the
conversion must use `--application-id run`. Merge the blueprint into the
.rrd: passing run.mcap and the .rbl to `rerun` together does not apply it.
"""

import sys

import rerun.blueprint as rrb

APPLICATION_ID = "run"


def blueprint() -> rrb.Blueprint:
    arms = rrb.Spatial3DView(
        name="Arms (URDF posed by /tf)",
        origin="/",
        eye_controls=rrb.EyeControls3D(
            position=(0.12, -0.46, 0.44),  # in front of the arms, to the slave's side, above
            look_target=(0.02, 0.0, 0.18),  # middle of the workspace
            eye_up=(0.0, 0.0, 1.0),
        ),
    )
    plots = rrb.Vertical(
        rrb.TimeSeriesView(name="master joint positions", origin="/master/joint_states/position"),
        rrb.TimeSeriesView(name="slave joint positions", origin="/slave/joint_states/position"),
        rrb.TimeSeriesView(name="slave joint efforts", origin="/slave/joint_states/effort"),
    )
    return rrb.Blueprint(
        rrb.Horizontal(arms, plots, column_shares=[3, 2]),
        rrb.BlueprintPanel(state="collapsed"),
        rrb.SelectionPanel(state="collapsed"),
        rrb.TimePanel(state="collapsed"),
    )


def main() -> None:
    if len(sys.argv) != 2:
        sys.exit("usage: python3 tactile_blueprint.py OUT.rbl")
    blueprint().save(APPLICATION_ID, sys.argv[1])


if __name__ == "__main__":
    main()
