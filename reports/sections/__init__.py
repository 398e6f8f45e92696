"""The report's sections, in the order they appear. A section is a module with
plan(ctx) -> [Run] (the runs it needs; runs are shared by tag) and
write(ctx) -> (markdown lines, cross-check failures). A new section: one file, one line here."""
import os
import sys

# The sections read runs through the floedem package: python/ in a checkout (share/floedem/python
# installed), beside reports/.
_PYTHON = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__)))), "python")
if _PYTHON not in sys.path:
    sys.path.insert(0, _PYTHON)

from sections import (channel, cost_error, decisions, engines, field, hindcast, impacts, observations,  # noqa: E402
                      sensitivity, speed, stress, threads, towing)

SECTIONS = [impacts, towing, decisions, field, channel, hindcast, observations, sensitivity, stress, speed, threads,
            cost_error, engines]
