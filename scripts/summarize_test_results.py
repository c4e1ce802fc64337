#!/usr/bin/env python3
"""Sums up the JUnit XML files that catkin's run_tests writes, lists failures, prints the time of
each test binary, rostest and pytest run (the rostests' own node results, rosunit-*.xml, are part
of their rostest's time), and one closing line "tests: N passed, N failed, N skipped". Exit status
1 when a test failed or errored, or when no test ran at all."""
import glob
import os
import sys
import xml.etree.ElementTree as ET


def seconds(root):
    """The run time [s] a result file records: its root's, else the sum of its test suites'."""
    if root.get("time") is not None:
        return float(root.get("time"))
    return sum(float(suite.get("time") or 0) for suite in root.iter("testsuite"))


def main(results_dir):
    passed = failed = skipped = 0
    failures = []
    times = []
    files = sorted(glob.glob(os.path.join(results_dir, "**", "*.xml"), recursive=True))
    for path in files:
        try:
            root = ET.parse(path).getroot()
        except ET.ParseError as err:
            failures.append(f"{path}: unreadable result file ({err})")
            failed += 1
            continue
        name = os.path.basename(path)
        if not name.startswith("rosunit-"):
            times.append((seconds(root), name[: -len(".xml")]))
        suites = [root] if root.tag == "testsuite" else root.iter("testsuite")
        for suite in suites:
            for case in suite.iter("testcase"):
                name = f"{case.get('classname', '')}.{case.get('name', '')}"
                if case.find("failure") is not None or case.find("error") is not None:
                    failed += 1
                    node = case.find("failure")
                    if node is None:
                        node = case.find("error")
                    message = (node.get("message") or node.text or "").strip().splitlines()
                    failures.append(f"{name}: {message[0] if message else 'failed'}")
                elif case.find("skipped") is not None or case.get("status") == "notrun":
                    skipped += 1
                else:
                    passed += 1
    print(f"== {len(files)} result files in {results_dir}")
    print("== time per test binary / rostest / pytest run [s] (with -j2 run_tests runs two at once)")
    for secs, name in sorted(times, reverse=True):
        print(f"{secs:8.1f}  {name}")
    print(f"{sum(secs for secs, _ in times):8.1f}  sum")
    for line in failures:
        print(f"FAILED {line}")
    print(f"tests: {passed} passed, {failed} failed, {skipped} skipped")
    if passed + failed == 0:
        print("no test ran", file=sys.stderr)
        return 1
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "build/test_results"))
