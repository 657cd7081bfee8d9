"""fvp.sim's trial keywords are `fvp run`'s options: none missing, the automatic stop's
switches with the CLI's defaults, and each reaching the trial."""
import re
import subprocess

import pytest

import fvp

# `fvp run` options whose keyword is not the option's name with '-' as '_', each with why.
RENAMED = {
    "--world": "world_config",     # a keyword says what the file holds, as Trial's options do
    "--config": "planner_config",  # ditto: the planner's config, beside world_ and arm_config
    "--arm": "arm_config",         # ditto
    "--out": "out_dir",            # optional in Python (no files unless asked for)
    "--remember": "remembered_visit",  # a keyword says what it holds: the earlier visit
}
# `fvp run` options with no keyword at all, each with why.
NOT_KEYWORDS = {
    "--help": "the CLI's own",
    # The CLI's ROS bag recorder (apps/stereo_bag_files.h, over TrialOptions::on_frame); the
    # Python module does not link the ROS layer, and has no frame hook yet.
    "--bag": "the CLI's ROS bag recorder",
}


def run_options(fvp_exe):
    """The long options of `fvp run --help`, a negated flag's --no- form left out."""
    text = subprocess.run([fvp_exe, "run", "--help"], check=True, capture_output=True,
                          text=True).stdout
    names = set()
    for line in text.splitlines():
        # An option's line: its names first ("-h,--help", "--stop TEXT:{budget,auto}=budget").
        if not line.lstrip().startswith("-"):
            continue
        for name in re.findall(r"--[a-z][a-z0-9-]*", line.split()[0]):
            if not name.startswith("--no-"):
                names.add(name)
    return names


def keyword_defaults(function):
    """The keywords of a function whose keywords are generated from the run's settings, and
    their defaults, from its docstring's lines "  key (default: value): help"."""
    return dict(re.findall(r"^  (\w+) \(default: (.*?)\): ", function.__doc__, re.M))


def keywords(function):
    return set(keyword_defaults(function))


def keyword_for(option):
    return RENAMED.get(option, option[2:].replace("-", "_"))


def test_every_run_option_has_a_keyword(fvp_exe):
    options = run_options(fvp_exe)
    # The parse found the options (a changed help layout would make this test vacuous).
    assert {"--planner", "--seed", "--stop", "--confirm-detections", "--out"} <= options
    for function in (fvp.sim.Trial, fvp.sim.run_trial):
        missing = sorted(o for o in options - NOT_KEYWORDS.keys()
                         if keyword_for(o) not in keywords(function))
        assert not missing, f"{function.__qualname__}: no keyword for {missing}"


def test_exceptions_are_still_options(fvp_exe):
    # A stale exception would hide nothing, but says something false about the CLI.
    options = run_options(fvp_exe)
    assert set(RENAMED) <= options and set(NOT_KEYWORDS) <= options


def test_automatic_stop_switches_default_as_the_cli(fvp_exe):
    defaults = keyword_defaults(fvp.sim.Trial)
    assert defaults["confirm_detections"] == "true"
    assert defaults["release_left_out"] == "true"
    assert defaults["seek_partly_seen"] == "true"
    assert defaults["known_fruitlets"] == "true"
    help_text = subprocess.run([fvp_exe, "run", "--help"], check=True, capture_output=True,
                               text=True).stdout
    # The CLI's flags are on unless negated (TrialOptions' defaults).
    assert "--confirm-detections,--no-confirm-detections" in help_text
    assert "--release-left-out,--no-release-left-out" in help_text
    assert "--seek-partly-seen,--no-seek-partly-seen" in help_text
    assert "--known-fruitlets,--no-known-fruitlets" in help_text


@pytest.mark.parametrize("confirm,release,seek,known",
                         [(False, True, True, False), (True, False, False, True)])
def test_automatic_stop_switches_reach_the_trial(confirm, release, seek, known):
    result = fvp.sim.run_trial(seed=2, clock="fixed", stop="auto", max_views=1,
                               confirm_detections=confirm, release_left_out=release,
                               seek_partly_seen=seek, known_fruitlets=known)
    assert result["stop"]["rule"] == "auto"
    assert result["stop"]["confirm_detections"] is confirm
    assert result["stop"]["release_left_out"] is release
    assert result["stop"]["seek_partly_seen"] is seek
    assert result["stop"]["known_fruitlets"] is known


def test_automatic_stop_switches_default_on():
    result = fvp.sim.Trial(seed=2, clock="fixed", stop="auto", max_views=1).run()
    assert result["stop"]["confirm_detections"] is True
    assert result["stop"]["release_left_out"] is True
    assert result["stop"]["seek_partly_seen"] is True
    assert result["stop"]["known_fruitlets"] is True


def test_the_field_preset_runs_with_view_registration_unless_told_otherwise():
    # The preset carries the run setting it is meant to be run with (run_register_views: 1);
    # an explicit keyword (--register-views / --no-register-views) decides over it.
    import os
    field = os.path.join(os.environ.get("FVP_SOURCE_DIR", "."),
                         "robot/sim/config/world_field.yaml")
    quick = dict(max_views=1, clock="fixed", backend="cpu")
    assert fvp.sim.run_trial(world_config=field, **quick)["register_views"] is True
    assert fvp.sim.run_trial(world_config=field, register_views=False,
                             **quick)["register_views"] is False
    assert fvp.sim.run_trial(**quick)["register_views"] is False


def test_result_settings_are_the_keywords():
    # One list makes the keywords and result.json's settings: the same keys, and a trial's
    # settings read back as keywords give the same settings. Where files go and the visit a
    # trial remembers are not settings (a season's visits share settings; the remembered visit
    # is the result's own "remembered_visit").
    result = fvp.sim.run_trial(seed=2, clock="fixed", max_views=1, backend="cpu")
    settings = result["settings"]
    assert set(settings) == keywords(fvp.sim.Trial) - {"out_dir", "remembered_visit"}
    assert settings["clock"] == "fixed" and settings["backend"] == "cpu"
    assert settings["max_views"] == 1 and settings["stop"] == "budget"
    again = fvp.sim.run_trial(**{k: v for k, v in settings.items() if v is not None})
    assert again["settings"] == settings


def test_bad_keywords_name_themselves():
    with pytest.raises(TypeError, match="unexpected keyword argument 'budget'"):
        fvp.sim.Trial(budget=10)
    with pytest.raises(ValueError, match="stop: expected one of budget, auto, got 'soon'"):
        fvp.sim.Trial(stop="soon")
    with pytest.raises(ValueError, match="backend: expected one of auto, cpu, opencl, vulkan"):
        fvp.sim.run_trial(backend="gpu")
    with pytest.raises(ValueError, match="budget_s: expected a number, got 'x'"):
        fvp.sim.run_trial(budget_s="x")
    with pytest.raises(ValueError, match="setting 'budget_s': expected a positive number"):
        fvp.sim.run_trial(budget_s=-1.0)


def test_the_setups_keywords_are_the_trials():
    # fvp.NbvSetup's keywords come from the same descriptions: each is a trial keyword except
    # those a trial sets itself (its perception, from the world) or the loop's own.
    setup = keyword_defaults(fvp.NbvSetup)
    assert set(setup) - keywords(fvp.sim.Trial) == {"perception",
                                                   "max_consecutive_dropped_frames"}
    with pytest.raises(TypeError, match="NbvSetup: unexpected keyword argument 'clock'"):
        fvp.NbvSetup(clock="fixed")
    with pytest.raises(ValueError, match="NbvSetup: max_views: expected an integer"):
        fvp.NbvSetup(max_views=2.5)


def test_the_view_ordering_is_a_setting_that_reaches_the_trial():
    # Views tried by information per second of move plus the overhead (0: planner's order).
    assert float(keyword_defaults(fvp.sim.Trial)["view_overhead_s"]) == pytest.approx(1.3)
    assert float(keyword_defaults(fvp.NbvSetup)["view_overhead_s"]) == pytest.approx(1.3)
    result = fvp.sim.run_trial(seed=2, clock="fixed", max_views=1, view_overhead_s=0.0)
    assert result["settings"]["view_overhead_s"] == 0.0
    with pytest.raises(ValueError, match="setting 'view_overhead_s': expected a finite number"):
        fvp.sim.run_trial(view_overhead_s=-1.0)


def test_the_simulated_robot_charges_perception_as_it_is_told():
    # On the fixed clock perception costs what the setup's stereo pass costs: SGBM's 0.4 s by
    # default; a Robot for NbvSetup(guided_stereo=True) is given the guided pass's 0.2 s.
    with pytest.raises(ValueError, match="sim.Robot: fixed_perception_time_s: expected"):
        fvp.sim.Robot(fixed_perception_time_s=-1.0)
    with pytest.raises(ValueError, match="fixed_perception_time_s"):
        fvp.sim.Robot(fixed_perception_time_s=float("nan"))
    assert "0.2 s for NbvSetup(guided_stereo=True)" in fvp.sim.Robot.__doc__
