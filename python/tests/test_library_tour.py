"""The library is the whole system: a Python camera and arm (each delegating to the
simulator's) run a tree of four clusters through fvp.NbvSetup, the library's setup (not
fvp.sim.Trial), and reproduce `fvp run --world world_tree.yaml --clock fixed` exactly: the same
clusters in the same order, the same views and poses, the same sizes and the same simulated
time. The heavy case is the issue's: the automatic stop, no view cap."""
import json
import os
import subprocess

import numpy as np
import pytest

import fvp

TREE = os.path.join(os.environ.get("FVP_SOURCE_DIR", "."), "robot/sim/config/world_tree.yaml")


class DelegatingCamera(fvp.Camera):
    def __init__(self, inner):
        super().__init__()
        self.inner = inner

    def capture(self, T_world_camera):
        return self.inner.capture(T_world_camera)


class DelegatingArm(fvp.Arm):
    def __init__(self, inner):
        super().__init__()
        self.inner = inner

    def camera_pose(self):
        return self.inner.camera_pose()

    def reachable(self, T_world_camera):
        return self.inner.reachable(T_world_camera)

    def move_to(self, T_world_camera):
        return self.inner.move_to(T_world_camera)

    def update_obstacles(self, map):
        return self.inner.update_obstacles(map)

    def check_goal(self, T_world_camera):
        return self.inner.check_goal(T_world_camera)

    def travel_time_s(self, T_world_from_camera, T_world_to_camera):
        return self.inner.travel_time_s(T_world_from_camera, T_world_to_camera)


class ClusterLog:
    """A tour observer: which clusters started and finished, in order."""

    def __init__(self):
        self.started, self.done = [], []

    def on_cluster_start(self, index):
        self.started.append(index)

    def on_cluster_done(self, visit):
        self.done.append(visit["index"])


def cli_tree(fvp_exe, out, seed, stop, max_views):
    args = [fvp_exe, "run", "--world", TREE, "--seed", str(seed), "--clock", "fixed", "--stop",
            stop, "--backend", "cpu", "--out", str(out)]
    if max_views is not None:
        args += ["--max-views", str(max_views)]
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    return json.loads((out / "result.json").read_text())


def library_tree(seed, stop, max_views):
    robot = fvp.sim.Robot(seed=seed, world_config=TREE, clock="fixed")
    setup = fvp.NbvSetup(planner="fvp", seed=seed, stop=stop, max_views=max_views,
                         backend="cpu")
    log = ClusterLog()
    tour = setup.run_tour(camera=DelegatingCamera(robot.camera), arm=DelegatingArm(robot.arm),
                          targets=robot.targets, clock=robot.clock, observer=log)
    return robot, tour, log


def assert_same_tour(cli, robot, tour, log):
    visits = tour["visits"]
    assert [v["index"] for v in visits] == cli["tour"]["order"]
    assert log.done == [v["index"] for v in visits if v["run"] is not None]
    by_index = {c["index"]: c for c in cli["clusters"]}
    poses = []
    for v in visits:
        c = by_index[v["index"]]
        assert v["status"] == c["status"]
        if v["run"] is None:
            continue
        run = v["run"]
        assert run["views"] == c["views"]
        assert run["stop_reason"] == c["stop_reason"]
        poses += run["camera_poses"]
        ours = [d["size_mm"] for d in run["sizing"]["sized_fruitlets"]]
        theirs = [d["size_mm"] for d in c.get("sized_fruitlets", [])]
        np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-9)
        centres = [d["center_m"] for d in run["sizing"]["sized_fruitlets"]]
        np.testing.assert_allclose(centres, [d["center_m"] for d in c.get("sized_fruitlets", [])],
                                   rtol=0, atol=1e-9)
    assert len(poses) == cli["views"]
    np.testing.assert_allclose([T[:3, 3] for T in poses], cli["camera_path_m"], rtol=0, atol=1e-9)
    for T, view in zip(poses, cli["view_log"]):
        np.testing.assert_allclose(T[:3, 2], view["viewing_direction"], rtol=0, atol=1e-9)
    assert tour["transit_s"] == pytest.approx(cli["tour"]["transit_sim_s"], abs=1e-9)
    # The fixed clock charges the same on any machine: the same simulated time, exactly.
    assert robot.clock.now_s() == cli["sim_time_s"]


def test_library_tour_matches_fvp_run_two_views_a_cluster(fvp_exe, tmp_path):
    cli = cli_tree(fvp_exe, tmp_path / "cli", seed=1, stop="budget", max_views=2)
    robot, tour, log = library_tree(seed=1, stop="budget", max_views=2)
    assert len(tour["visits"]) == 4
    assert_same_tour(cli, robot, tour, log)


@pytest.mark.heavy
def test_library_tour_with_the_automatic_stop_matches_fvp_run(fvp_exe, tmp_path):
    cli = cli_tree(fvp_exe, tmp_path / "cli", seed=1, stop="auto", max_views=None)
    robot, tour, log = library_tree(seed=1, stop="auto", max_views=None)
    assert len(tour["visits"]) == 4
    assert all(v["run"] is None or v["run"]["stop_reason"] in ("cluster_done", "budget",
                                                                "no_reachable_view")
               for v in tour["visits"])
    assert_same_tour(cli, robot, tour, log)
