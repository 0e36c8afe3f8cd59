#!/usr/bin/env python3
"""A planted fault: a row whose Source gives a short commit, which is not a citation.

Source   a/b@1234567:src/x.py:encode, the commit abbreviated to seven digits
Config   no shipped config
Theory   none; the command refuses the file before any audit.
Expect   actions: none; observation: none
"""
raise SystemExit("never run: the command refuses this plug-in before starting it")
