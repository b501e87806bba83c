#!/usr/bin/env python3
"""Every test of a build carries exactly one tier label: unit, scene or e2e (tests/CMakeLists.txt).

Usage: test_tiers.py CTEST BUILD_DIR
Lists the build's tests with `ctest --show-only=json-v1` and exits 1 naming every test with no
tier or with more than one. A suite whose executable is not built yet lists no tests of its own,
so this runs in the suite (after the build), not at configure time.
"""
import json
import subprocess
import sys

TIERS = {"unit", "scene", "e2e"}


def main():
    ctest, build = sys.argv[1], sys.argv[2]
    out = subprocess.run([ctest, "--show-only=json-v1"], cwd=build, capture_output=True,
                         text=True, check=True)
    tests = json.loads(out.stdout)["tests"]
    counts = {t: 0 for t in sorted(TIERS)}
    bad = []
    for test in tests:
        labels = []
        for prop in test.get("properties", []):
            if prop["name"] == "LABELS":
                labels = prop["value"]
        tiers = [label for label in labels if label in TIERS]
        if len(tiers) != 1:
            bad.append(f"{test['name']}: labels {labels or 'none'}")
        else:
            counts[tiers[0]] += 1
    print(", ".join(f"{n} {t}" for t, n in counts.items()) + f" of {len(tests)} tests")
    if not tests:
        print("test_tiers: no test listed")
        return 1
    for line in bad:
        print("test_tiers: not in exactly one tier:", line)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
