"""The report's sections, in the order they appear. A section is a module with
plan(ctx) -> [Run] (the runs it needs; runs are shared by tag) and
write(ctx) -> (markdown lines, cross-check failures). A new section: one file, one line here."""
from sections import channel, cost_error, engines, field, impacts, speed, stress, threads, towing

SECTIONS = [impacts, towing, field, channel, stress, speed, threads, cost_error, engines]
