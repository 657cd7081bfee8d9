"""The mapping/planning session from numpy: frames in, the next best view, batch information
gain, surface points, clusters and sizes out; bad input is a ValueError naming the argument."""
import numpy as np
import pytest

import fvp


@pytest.fixture(scope="module")
def seed2_frames():
    """Seed 2's start view and two more along the orbit, rendered by the simulator's camera."""
    trial = fvp.sim.Trial(seed=2, clock="fixed", backend="cpu")
    T0 = trial.arm.camera_pose()
    frames = [trial.camera.capture(T0).frame]
    for dx in (0.03, -0.03):
        T = T0.copy()
        T[0, 3] += dx
        frames.append(trial.camera.capture(T).frame)
    return frames


def numpy_frame(frame, **extra):
    """The same view rebuilt from numpy arrays, as a robot's driver would hand it over."""
    return fvp.StereoFrame(np.array(frame.left), np.array(frame.right), frame.intrinsics,
                           np.array(frame.T_world_camera), **extra)


def test_frame_arrays_round_trip(seed2_frames):
    f = seed2_frames[0]
    k = f.intrinsics
    assert f.left.shape == (k.height_px, k.width_px, 3) and f.left.dtype == np.uint8
    assert f.T_world_camera.shape == (4, 4)
    g = numpy_frame(f)
    assert np.array_equal(g.left, f.left) and np.array_equal(g.right, f.right)
    assert np.array_equal(g.T_world_camera, f.T_world_camera)
    assert g.fruitlet_mask is None
    # A uint16 mask is an instance segmentation, kept as its ids; others become 0 / 255.
    ids = np.zeros((k.height_px, k.width_px), np.uint16)
    ids[10:20, 10:20], ids[10:20, 20:30] = 7, 300
    m = numpy_frame(f, fruitlet_mask=ids).fruitlet_mask
    assert m.dtype == np.uint16 and np.array_equal(m, ids)
    m = numpy_frame(f, fruitlet_mask=ids.astype(np.int32)).fruitlet_mask
    assert m.dtype == np.uint8 and set(np.unique(m)) == {0, 255}


def test_session_maps_plans_and_sizes(seed2_frames):
    session = fvp.MappingSession(backend="cpu")
    assert session.region is None
    views = [session.add_view(numpy_frame(f)) for f in seed2_frames]
    assert views[0]["tag_detected"] and views[0]["integrated"]
    assert session.views == 3
    region = session.region
    assert region["center_m"].shape == (3,) and 0 < region["radius_m"] < 0.2

    planner = fvp.Planner("fvp", seed=2, backend="cpu")
    T_now = seed2_frames[-1].T_world_camera
    plan = planner.next_best_view(session, T_now)
    c = plan["candidates"]
    n = len(c["kind"])
    assert n > 0 and c["T_world_camera"].shape == (n, 4, 4) and c["target_m"].shape == (n, 3)
    assert plan["chosen"] is not None
    assert np.array_equal(plan["T_world_camera"], c["T_world_camera"][plan["chosen"]])
    assert c["utility"][plan["chosen"]] == c["utility"][c["reachable"]].max()

    # Batch information gain of the same poses equals the planner's own scores (single ray,
    # the default planner config's mode).
    ig = fvp.info_gain(session, c["T_world_camera"], c["target_m"], backend="cpu")
    assert ig.shape == (n,)
    np.testing.assert_allclose(ig[c["reachable"]], c["ig"][c["reachable"]], rtol=0, atol=1e-12)

    surface = session.surface_points()
    assert surface.ndim == 2 and surface.shape[1] == 3 and len(surface) > 100
    sized = session.size_fruitlets()
    assert len(sized["sized_fruitlets"]) >= 1
    assert sized["points"].shape[0] == sized["labels"].shape[0]
    for f in sized["sized_fruitlets"]:
        assert 3.0 < f["size_mm"] < 30.0


def test_registered_views_report_the_maps_offset(seed2_frames):
    # The third view told 2 mm off: registration moves it back, the registered map's offset
    # is estimated from that, and the sized positions are moved by it.
    off = numpy_frame(seed2_frames[2])
    pose = np.array(off.T_world_camera)
    pose[0, 3] += 0.002
    moved = fvp.StereoFrame(np.array(off.left), np.array(off.right), off.intrinsics, pose)
    plain = fvp.MappingSession(backend="cpu")
    assert plain.anchor_offset["views"] == 0 and not plain.anchor_offset["applied"]
    session = fvp.MappingSession(backend="cpu", register_views=True)
    for f in (seed2_frames[0], seed2_frames[1], moved):
        session.add_view(f)
    offset = session.anchor_offset
    assert offset["applied"] and offset["views"] >= 2
    assert offset["shift_m"].shape == (3,) and np.isfinite(offset["shift_m"]).all()
    assert 0.0 < np.linalg.norm(offset["shift_m"]) < 0.01
    assert len(session.size_fruitlets()["sized_fruitlets"]) >= 1


def test_a_reachability_filter_from_python(seed2_frames):
    session = fvp.MappingSession(backend="cpu")
    for f in seed2_frames:
        session.add_view(f)
    planner = fvp.Planner("fvp", seed=2, backend="cpu")
    plan = planner.next_best_view(session, seed2_frames[0].T_world_camera,
                                  reachable=lambda T: T[2, 3] > 10.0)  # nothing is that high
    assert plan["T_world_camera"] is None and plan["chosen"] is None
    assert not plan["candidates"]["reachable"].any()


def test_bad_input_names_the_argument(seed2_frames):
    f = seed2_frames[0]
    with pytest.raises(ValueError, match="left"):
        fvp.StereoFrame(np.zeros((10, 10, 3), np.uint8), f.right, f.intrinsics, f.T_world_camera)
    with pytest.raises(ValueError, match="left: expected a uint8 BGR image, got dtype float32"):
        fvp.StereoFrame((f.left / 255.0).astype(np.float32), f.right, f.intrinsics,
                        f.T_world_camera)
    with pytest.raises(ValueError, match="right: expected shape"):
        fvp.StereoFrame(f.left, np.zeros((0, 4, 3), np.uint8), f.intrinsics, f.T_world_camera)
    with pytest.raises(ValueError, match="fruitlet_mask: expected an integer or bool mask"):
        numpy_frame(f, fruitlet_mask=np.full(f.left.shape[:2], 0.5))
    bad_pose = np.array(f.T_world_camera)
    bad_pose[:3, :3] *= 2.0
    with pytest.raises(ValueError, match="T_world_camera"):
        fvp.StereoFrame(f.left, f.right, f.intrinsics, bad_pose)
    with pytest.raises(ValueError, match="fruitlet_mask"):
        numpy_frame(f, fruitlet_mask=np.zeros((5, 5), np.uint8))
    with pytest.raises(ValueError, match="unknown planner 'nope'"):
        fvp.Planner("nope")
    with pytest.raises(ValueError, match="unknown map engine"):
        fvp.MappingSession(engine="voxblox")
    with pytest.raises(RuntimeError, match="no map yet"):
        fvp.info_gain(fvp.MappingSession(backend="cpu"), np.eye(4)[None], np.zeros((1, 3)))


def test_registries_list_what_is_built_in():
    assert fvp.planners()[:2] == ["fvp", "rvp"]
    assert fvp.map_engines()[:2] == ["grid", "octomap"]
    assert fvp.backends()["cpu"] == "available"


class DroppingCamera(fvp.Camera):
    """Drops every second frame (returns None), else renders through the simulator."""

    def __init__(self, inner):
        super().__init__()
        self.inner, self.calls = inner, 0

    def capture(self, T_world_camera):
        self.calls += 1
        return None if self.calls % 2 == 0 else self.inner.capture(T_world_camera)


class SimArm(fvp.Arm):
    def __init__(self, inner):
        super().__init__()
        self.inner = inner

    def camera_pose(self):
        return self.inner.camera_pose()

    def reachable(self, T):
        return self.inner.reachable(T)

    def move_to(self, T):
        return self.inner.move_to(T)


def loop_parts(seed):
    """A simulated world (its camera and arm), an empty session and FVP, for run_nbv."""
    trial = fvp.sim.Trial(seed=seed, clock="fixed", backend="cpu")
    return trial, fvp.MappingSession(backend="cpu"), fvp.Planner("fvp", seed=seed, backend="cpu")


def test_run_nbv_with_a_python_stop_predicate_and_dropped_frames():
    trial, session, planner = loop_parts(seed=2)
    seen = []

    class Log:
        def on_view(self, view):
            seen.append(view["index"])

    stop = fvp.StopCondition(lambda s: s.views >= 3, "three_views") | fvp.StopCondition.budget(1e6)
    result = fvp.run_nbv(session, planner, DroppingCamera(trial.camera), SimArm(trial.arm), stop,
                         observer=Log())
    assert result["stop_reason"] == "three_views"
    assert result["views"] == 3 and seen == [0, 1, 2]
    assert result["events"]["dropped_frames"] >= 2
    assert len(result["camera_poses"]) == 3


class TimingOutArm(SimArm):
    """Every plan times out; a move reports how it ended."""

    def move_to(self, T):
        return fvp.MoveResult(fvp.MoveStatus.timeout, planning_wall_s=1.0)


def test_run_nbv_ends_an_iteration_after_max_failed_plans():
    trial, session, planner = loop_parts(seed=2)
    plans = []

    class Log:
        def on_plan(self, plan):
            plans.append(plan)

    stop = fvp.StopCondition(lambda s: s.iterations >= 2, "two_iterations")
    result = fvp.run_nbv(session, planner, trial.camera, TimingOutArm(trial.arm), stop,
                         observer=Log(), max_failed_plans=2)
    assert result["events"]["move_attempts"] == 4  # two per iteration, then it gives up
    assert result["events"]["iterations_ended_by_failed_plans"] == 2
    assert result["events"]["retreats"] == 0
    assert [p["ended_by_failed_plans"] for p in plans] == [True, True]
    assert fvp.MoveResult(fvp.MoveStatus.success, retreated=True).retreated
    assert not fvp.MoveResult(fvp.MoveStatus.success).retreated


def test_size_captures_is_fvp_size_as_a_function(capture_set, tmp_path):
    result = fvp.size_captures(str(capture_set), out_dir=str(tmp_path / "sized"), backend="cpu")
    assert result["cluster_region_found"]
    assert len(result["sized_fruitlets"]) >= 1
    assert result["metrics"]["match_percent"] > 0  # the set carries ground_truth.json
    assert (tmp_path / "sized" / "fruitlets.json").exists()


def test_callbacks_that_answer_yes_or_no_take_a_bool_only():
    # One rule for every such callback: True/False (or a numpy bool); None, a str or an int
    # is an error naming the callback, never taken as False.
    state = fvp.LoopState()
    assert fvp.StopCondition(lambda s: True, "t").check(state)
    assert not fvp.StopCondition(lambda s: np.bool_(False), "f").check(state)
    for bad, shown in [(None, "None"), ("yes", "str"), (1, "int")]:
        with pytest.raises(ValueError, match="StopCondition predicate: expected a bool .*got " + shown):
            fvp.StopCondition(lambda s, v=bad: v, "x").check(state)
