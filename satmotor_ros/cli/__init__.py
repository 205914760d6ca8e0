# SPDX-License-Identifier: Apache-2.0
"""The ``satmotor`` command line: hydraulic units in, SI inside."""

import os

# One BLAS thread: the commands' linear algebra is on matrices of a few columns, where more
# threads only contend (a least-squares SVD of 10^4 x 7 took 54 ms with 2 threads on a busy
# 2-core machine, 2.4 ms with 1). Set before numpy is first imported; the user's value wins.
for _name in ('OPENBLAS_NUM_THREADS', 'OMP_NUM_THREADS', 'MKL_NUM_THREADS'):
    os.environ.setdefault(_name, '1')

try:  # numpy, scipy and matplotlib take a while: a Ctrl-C meanwhile is no error
    from satmotor_ros.cli.main import main  # noqa: E402
except KeyboardInterrupt:
    import sys  # noqa: E402

    print('satmotor: interrupted while starting; nothing was written', file=sys.stderr)
    raise SystemExit(130) from None

__all__ = ['main']
