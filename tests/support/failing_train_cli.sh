#!/bin/sh
# A stand-in for the handcentric CLI whose `train` always fails and whose other subcommands are
# the real one's ($REAL_HANDCENTRIC): experiments/table1.sh must stop on it and name the cell.
if [ "$1" = train ]; then
  echo "handcentric: error: planted failure" >&2
  exit 1
fi
exec "$REAL_HANDCENTRIC" "$@"
