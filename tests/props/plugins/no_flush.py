#!/usr/bin/env python3
"""A plug-in that answers correctly but never flushes, so its answers stay in its buffer.

Each answer (six zeros, the right id) is written with sys.stdout.write and no flush. On a pipe,
Python holds stdout in a block buffer; here it is made a 1 MiB buffer explicitly, so that
neither `python3 -u` nor PYTHONUNBUFFERED can let an answer out early (a few hundred bytes each:
thousands of answers before the buffer would fill).

What the audit should find: no answer to request 0 within --timeout (the timeout message, which
should suggest flushing), then it kills the process group. Not a hang.
"""
import io
import json
import sys

# Our own block-buffered stdout: ignores -u and PYTHONUNBUFFERED, never flushes on a newline.
sys.stdout = io.TextIOWrapper(io.BufferedWriter(io.FileIO(sys.stdout.fileno(), "w", closefd=False),
                                                buffer_size=1 << 20),
                              line_buffering=False, write_through=False)
for line in sys.stdin:
    request = json.loads(line)
    sys.stdout.write(json.dumps({"id": request["id"], "actions": [0.0] * 6}) + "\n")  # no flush
