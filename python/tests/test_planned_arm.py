"""The real-robot arm from Python: fvp.PlannedArm plans with fvp's IK + OMPL and hands each
trajectory to a Python executor (times (N,), joints (N, 7)); the joints come from a Python
joint-state source. Here the "robot" is a list of joints the executor moves."""
import numpy as np
import pytest

import fvp


class FakeRobot(fvp.JointStateSource):
    """The driver's joint_states: the joints the executor last set."""

    def __init__(self, q):
        super().__init__()
        self.q = np.array(q, dtype=float)

    def joint_positions(self):
        return self.q


class RecordingExecutor(fvp.TrajectoryExecutor):
    """Records every trajectory; runs it (the joints jump to its end) unless told to refuse."""

    def __init__(self, robot, answer=fvp.ExecutionStatus.done):
        super().__init__()
        self.robot = robot
        self.answer = answer
        self.trajectories = []

    def execute(self, times_s, positions):
        self.trajectories.append((times_s.copy(), positions.copy()))
        if self.answer == fvp.ExecutionStatus.done:
            self.robot.q = positions[-1].copy()
        return self.answer


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    # A small workspace tree (seconds to build, no cache): enough for poses near home.
    config = tmp_path_factory.mktemp("arm") / "arm.yaml"
    config.write_text("workspace_samples: 200000\n")
    return fvp.ArmModel(str(config))


@pytest.fixture(scope="module")
def workspace(model):
    return fvp.WorkspaceTree(model)


def goal_pose(model):
    q = model.home_configuration()
    q[0], q[1] = -0.3, 0.4
    return model.camera_pose(q)


def make_arm(model, workspace, answer=fvp.ExecutionStatus.done):
    robot = FakeRobot(model.home_configuration())
    executor = RecordingExecutor(robot, answer)
    arm = fvp.PlannedArm(model, workspace, robot, executor, sample_period_s=0.05)
    arm.set_reproducible_motion_planning(3)
    return arm, robot, executor


def test_a_reachable_pose_is_planned_executed_and_reached(model, workspace):
    arm, robot, executor = make_arm(model, workspace)
    start = robot.q.copy()
    goal = goal_pose(model)
    assert workspace.reachable(goal) and arm.reachable(goal)
    result = arm.move_to(goal)
    assert result.status == fvp.MoveStatus.success and result.planning_wall_s > 0
    assert len(executor.trajectories) == 1
    times_s, positions = executor.trajectories[0]
    assert times_s.ndim == 1 and positions.shape == (len(times_s), 7)
    assert times_s[0] == 0 and np.all(np.diff(times_s) > 0)
    assert np.all(np.diff(times_s) <= 0.05 + 1e-12)
    assert np.array_equal(positions[0], start)
    np.testing.assert_allclose(model.camera_pose(positions[-1]), goal, atol=1e-6)
    np.testing.assert_allclose(arm.camera_pose(), goal, atol=1e-6)
    np.testing.assert_array_equal(arm.joints(), robot.q)


def test_the_goal_check_says_how_long_the_move_takes(model, workspace):
    arm, robot, executor = make_arm(model, workspace)
    assert arm.checks_goals
    reach = arm.check_goal(goal_pose(model))
    assert isinstance(reach, fvp.GoalReach)
    assert reach.check == fvp.GoalCheck.feasible and reach.travel_s > 0
    # From where the camera is, the time between two poses is the check's (a tour's cost).
    assert arm.travel_time_s(arm.camera_pose(), goal_pose(model)) == pytest.approx(
        reach.travel_s, rel=1e-9)
    # Free space: the move is the straight motion the check timed.
    arm.move_to(goal_pose(model))
    times_s, _ = executor.trajectories[0]
    assert times_s[-1] == pytest.approx(reach.travel_s, rel=1e-9)
    far = goal_pose(model)
    far[1, 3] += 3.0
    out_of_reach = arm.check_goal(far)
    assert out_of_reach.check == fvp.GoalCheck.no_ik and np.isnan(out_of_reach.travel_s)
    assert np.isnan(fvp.GoalReach(fvp.GoalCheck.feasible).travel_s)


def test_refusals_failures_and_planning_failures_are_statuses(model, workspace):
    arm, robot, executor = make_arm(model, workspace, fvp.ExecutionStatus.refused)
    before = arm.camera_pose()
    assert arm.move_to(goal_pose(model)).status == fvp.MoveStatus.refused
    np.testing.assert_array_equal(arm.camera_pose(), before)

    executor.answer = fvp.ExecutionResult(fvp.ExecutionStatus.failed, "protective stop")
    move = arm.move(goal_pose(model))
    assert move["status"] == fvp.MoveStatus.execution_failed
    assert move["execution"] == fvp.ExecutionStatus.failed and move["detail"] == "protective stop"

    far = before.copy()
    far[1, 3] += 3.0
    assert not arm.reachable(far)
    assert arm.move_to(far).status == fvp.MoveStatus.no_ik
    assert len(executor.trajectories) == 2  # nothing executed for the unreachable pose


def test_callables_drive_it_too_and_bad_answers_are_errors(model):
    q = [model.home_configuration()]
    calls = []

    def execute(times_s, positions):
        calls.append(len(times_s))
        q[0] = positions[-1]
        return True

    arm = fvp.PlannedArm(model, None, lambda: q[0], execute)  # None: exact IK reachability
    arm.set_reproducible_motion_planning(4)
    assert arm.move_to(goal_pose(model)).ok and len(calls) == 1

    def forgets_to_return(times_s, positions):
        q[0] = positions[-1]

    arm = fvp.PlannedArm(model, None, lambda: q[0], forgets_to_return)
    with pytest.raises(ValueError, match="ExecutionStatus"):
        arm.move_to(model.camera_pose(model.home_configuration()))
    with pytest.raises(ValueError, match="7 joints"):
        fvp.PlannedArm(model, None, lambda: [0.0, 1.0], execute).camera_pose()
    with pytest.raises(ValueError, match="callable"):
        fvp.PlannedArm(model, None, 3, execute)
    with pytest.raises(TypeError, match="does not define execute"):
        fvp.PlannedArm(model, None, lambda: q[0], fvp.TrajectoryExecutor()).move_to(
            model.camera_pose(model.home_configuration()))
