#!/bin/sh
# SPDX-License-Identifier: Apache-2.0
# Mutation-test the model (mutmut 3) in a scratch copy of the committed tree, from a venv of its
# own: nothing is installed into .venv and the worktree stays untouched.
#   bench/mutation.sh [FILE...]   default: every module of satmotor_ros/model
#   TESTS='test/test_a.py test/test_b.py' bench/mutation.sh FILE...   other tests than the model's
# Results: `cd /tmp/satmotor_mutation && /tmp/mut/bin/mutmut results`.
set -eu
work=/tmp/satmotor_mutation
[ -x /tmp/mut/bin/mutmut ] || python3 -m venv /tmp/mut
# the pinned runtime and test requirements (a model test may import the CLI and the bag
# readers), not ROS, the linters or the type checker
grep -v '^ros-\|colcon\|ament\|flake8\|pydocstyle\|mypy\|stubs' requirements.txt \
    > /tmp/mut/requirements.txt
/tmp/mut/bin/pip install -q mutmut -r /tmp/mut/requirements.txt
rm -rf "$work" && mkdir -p "$work"
git archive HEAD | tar -x -C "$work"
cd "$work"
files=${*:-$(find satmotor_ros/model -name "*.py" ! -name __init__.py | sort)}
{
    printf '\n[mutmut]\nsource_paths=satmotor_ros/\nalso_copy=\n    config/\nonly_mutate=\n'
    for f in $files; do printf '    %s\n' "$f"; done
    printf 'pytest_add_cli_args_test_selection=\n'
    for t in ${TESTS:-test/test_model_*.py}; do printf '    %s\n' "$t"; done
} >> setup.cfg
export ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
/tmp/mut/bin/mutmut run --max-children 2
/tmp/mut/bin/mutmut results
