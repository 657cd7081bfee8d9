"""fvp.season: visits' results (day, path) to growth rates, fates and fruit set, the same
object `fvp season` writes as season.json (docs/season.md)."""
import json
import os
import subprocess

import pytest

import fvp

DATA = os.path.join(os.environ.get("FVP_SOURCE_DIR", "."), "tests/season/data")


def test_two_visits_of_a_tree_match_the_command(fvp_exe, tmp_path):
    visits = [(4.0, os.path.join(DATA, "tree_day4.json")), (0.0, os.path.join(DATA, "tree_day0.json"))]
    season = fvp.season(visits)
    assert [v["day"] for v in season["visits"]] == [0.0, 4.0]
    assert season["fruit_set"]["percent"] == pytest.approx(60.0, abs=0.01)
    fates = [f["fate"] for c in season["clusters"] for f in c["fruitlets"]]
    assert fates == ["persists", "persists", "abscises", "persists", "gone"]
    subprocess.run([fvp_exe, "season", "--visit", f"4={visits[0][1]}", "--visit",
                    f"0={visits[1][1]}", "--out", str(tmp_path)], check=True,
                   stdout=subprocess.DEVNULL)
    assert json.loads((tmp_path / "season.json").read_text()) == season


def test_the_size_error_floor_widens_the_rates_errors():
    """size_error_floor_mm adds to every size's standard error in quadrature (docs/season.md):
    tag 3's third fruitlet states 0.25 and 0.2 mm on days 0 and 4."""
    visits = [(0.0, os.path.join(DATA, "tree_day0.json")), (4.0, os.path.join(DATA, "tree_day4.json"))]
    wide = fvp.season(visits, size_error_floor_mm=0.3)
    assert wide["config"]["size_error_floor_mm"] == 0.3
    rate = wide["clusters"][0]["fruitlets"][2]
    assert rate["growth_rate_standard_error_mm_per_day"] == pytest.approx(
        (0.0625 + 0.04 + 2 * 0.09) ** 0.5 / 4, abs=1e-12)
    with pytest.raises(ValueError, match="size_error_floor_mm"):
        fvp.season(visits, size_error_floor_mm=-0.1)


def test_a_missing_visit_is_an_error_naming_it():
    with pytest.raises(RuntimeError, match="no_such_visit.json: no such file or directory"):
        fvp.season([(0.0, os.path.join(DATA, "tree_day0.json")), (4.0, "/nonexistent/no_such_visit.json")])


def test_the_simulated_robot_visits_the_tree_on_a_later_day():
    """fvp.sim.Robot(season_day=D): the same tree grown D days (docs/simulation.md "A season"):
    its clusters' start views stay, their fruitlets' centroids move (grown, drooped, some
    fallen); a day past the season's range is refused naming the key."""
    tree = os.path.join(os.environ.get("FVP_SOURCE_DIR", "."), "robot/sim/config/world_season.yaml")
    day0 = fvp.sim.Robot(seed=3, world_config=tree, season_day=0.0)
    day7 = fvp.sim.Robot(seed=3, world_config=tree, season_day=7.0)
    assert len(day0.targets) == len(day7.targets) == 4
    for a, b in zip(day0.targets, day7.targets):
        assert (a.T_world_start_camera == b.T_world_start_camera).all()
        assert not (a.center_m == b.center_m).all()
    with pytest.raises(ValueError, match="season_day"):
        fvp.sim.Robot(seed=3, world_config=tree, season_day=99.0)


def test_a_later_visit_remembers_the_earlier_one(tmp_path):
    """fvp.sim.Trial(remembered_visit=...): each cluster of the later visit starts from what the
    earlier visit learned of it (docs/season.md "Visits remembered"); one that is not there is
    an error naming it."""
    tree = os.path.join(os.environ.get("FVP_SOURCE_DIR", "."), "robot/sim/config/world_season.yaml")
    common = dict(seed=3, world_config=tree, clock="fixed", backend="cpu", max_views=1)
    fvp.sim.Trial(season_day=0.0, out_dir=str(tmp_path / "day-0"), **common).run()
    later = fvp.sim.Trial(season_day=4.0, remembered_visit=str(tmp_path / "day-0"), **common).run()
    assert later["remembered_visit"] == str(tmp_path / "day-0")
    remembered = [c["memory"] for c in later["clusters"] if "memory" in c]
    assert remembered and all(m["fruitlets"] > 0 for m in remembered)
    with pytest.raises(RuntimeError, match="no_such_visit: no such file or directory"):
        fvp.sim.Trial(season_day=4.0, remembered_visit="/nonexistent/no_such_visit", **common)
