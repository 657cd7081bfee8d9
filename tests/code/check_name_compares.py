#!/usr/bin/env python3
"""No planner, map engine, stop or clock name is compared as a string outside the registries
and the run specification (issue 39): after parsing, code holds registry entries and enums.
Usage: check_name_compares.py SOURCE_DIR. Exits 1 listing each compare it finds."""
import pathlib
import re
import sys

NAMES = "fvp|rvp|grid|octomap|budget|auto|wall|fixed"
COMPARE = re.compile(r'(?:==|!=)\s*"(?:%s)"|"(?:%s)"\s*(?:==|!=)' % (NAMES, NAMES))
# Where names are defined and parsed: the registries, the enums' own string functions, and
# the experiment directory's reader (registry-free so that its fuzzing harness links alone;
# it checks the manifest's schema).
ALLOWED = {
    "host/src/planner/planner_registry.cpp",
    "host/src/map/map_engine_registry.cpp",
    "host/include/fvp/host/nbv/stop_rule.h",
    "robot/sim/src/sim_clock.cpp",
    "trials/src/experiment_directory.cpp",
    "accel/src/backend.cpp",  # the backend names' own parser
}
DIRS = ["apps", "host", "trials", "robot", "python/src", "accel"]


def main(root):
    root = pathlib.Path(root)
    found = []
    for d in DIRS:
        for path in sorted((root / d).rglob("*")):
            if path.suffix not in (".cpp", ".h") or str(path.relative_to(root)) in ALLOWED:
                continue
            for number, line in enumerate(path.read_text(errors="replace").splitlines(), 1):
                if COMPARE.search(line):
                    found.append(f"{path.relative_to(root)}:{number}: {line.strip()}")
    for f in found:
        print(f)
    print(f"{len(found)} name compares outside the registries and the run specification")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "."))
