#!/usr/bin/env bash
# Table 1 (Sec. 4.2): kept for old instructions; `handcentric table1 --help` has the options.
exec "${HANDCENTRIC:-$(dirname "$0")/../build/apps/handcentric}" table1 "$@"
