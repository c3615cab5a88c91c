#!/usr/bin/env python3
"""Every CTest test carries at least one label (docs/CONTRIBUTING.md, "Labels"), so that `ctest -L unit`,
`-L physics`, `-L cli`, `-L browser` together run the whole suite and `-LE slow` leaves out only what is slow.
usage: check_labels.py CTEST BUILD_DIR   (exit 1, listing the unlabelled tests, when any has none)
"""
import json
import subprocess
import sys

KNOWN = {'unit', 'physics', 'cli', 'browser', 'slow'}
ctest, build = sys.argv[1], sys.argv[2]
listing = json.loads(subprocess.run([ctest, '--test-dir', build, '--show-only=json-v1'], check=True,
                                    capture_output=True, text=True).stdout)
problems = []
for test in listing['tests']:
    labels = set()
    for prop in test.get('properties', []):
        if prop['name'] == 'LABELS':
            labels = set(prop['value'])
    if not labels - {'slow'}:
        problems.append('%s: no label of unit, physics, cli, browser' % test['name'])
    for label in sorted(labels - KNOWN):
        problems.append('%s: unknown label %s (known: %s)' % (test['name'], label, ', '.join(sorted(KNOWN))))
for p in problems:
    print(p)
print('%d tests, %d without a proper label' % (len(listing['tests']), len(problems)))
sys.exit(1 if problems else 0)
