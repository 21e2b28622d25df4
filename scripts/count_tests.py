#!/usr/bin/python3
"""Counts the test cases in catkin's JUnit XML results (gtest and rostest alike).

Prints one line per result file, then a final line 'N passed, N failed, N skipped'.
Exits 1 when a case failed or no case ran at all.

A rostest writes two files: rosunit-NAME.xml with the gtest cases of its test node, and
rostest-NAME.xml with one case for the launch as a whole. The cases are counted from the first;
the second counts only when it failed (the launch or the test node broke), so that nothing is
counted twice.
"""
import pathlib
import sys
import xml.etree.ElementTree as ElementTree


def count(path):
    passed = failed = skipped = 0
    failures, skips = [], []
    for case in ElementTree.parse(path).getroot().iter("testcase"):
        name = f"{case.get('classname', '')}.{case.get('name', '')}"
        if case.find("failure") is not None or case.find("error") is not None:
            failed += 1
            failures.append(name)
        elif case.find("skipped") is not None or case.get("result") == "skipped":
            skipped += 1
            reason = case.find("skipped").get("message", "") if case.find("skipped") is not None else ""
            skips.append(f"{name}: {reason.strip().splitlines()[-1] if reason.strip() else ''}")
        else:
            passed += 1
    return passed, failed, skipped, failures, skips


def main(results_dir):
    totals = [0, 0, 0]
    for path in sorted(pathlib.Path(results_dir).rglob("*.xml")):
        passed, failed, skipped, failures, skips = count(path)
        if path.name.startswith("rostest-"):
            passed = skipped = 0
            skips = []
        totals = [totals[0] + passed, totals[1] + failed, totals[2] + skipped]
        print(f"{path.name}: {passed} passed, {failed} failed, {skipped} skipped")
        for name in failures:
            print(f"  FAILED {name}")
        for line in skips:
            print(f"  skipped {line}")
    print(f"{totals[0]} passed, {totals[1]} failed, {totals[2]} skipped")
    return 0 if totals[1] == 0 and totals[0] > 0 else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1]))
