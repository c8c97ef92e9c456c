#!/usr/bin/env python3
"""Counts the gtest/rostest JUnit results; prints 'N passed, N failed'; non-zero on any failure."""
import glob
import os
import sys
import xml.etree.ElementTree as ET

results_dir = sys.argv[1]
files = sorted(glob.glob(os.path.join(results_dir, "**", "*.xml"), recursive=True))
passed = failed = 0
failures = []
for path in files:
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        failed += 1
        failures.append(f"{path}: unreadable result file ({exc})")
        continue
    for case in root.iter("testcase"):
        if case.find("skipped") is not None:
            continue
        bad = case.find("failure") if case.find("failure") is not None else case.find("error")
        if bad is None:
            passed += 1
        else:
            failed += 1
            failures.append(f"{case.get('classname')}.{case.get('name')}: {(bad.get('message') or '').strip()[:300]}")
for line in failures:
    print("FAILED:", line)
if not files:
    print("no test results found in", results_dir)
    failed += 1
print(f"{passed} passed, {failed} failed")
sys.exit(1 if failed else 0)
