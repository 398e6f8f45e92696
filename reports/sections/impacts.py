"""Impacts: impulses and restitution on every engine, collision durations and forces
(reports/impact_suite.py does the work; this adapts it to the report)."""
import impact_suite


def plan(ctx):
    return impact_suite.plan(ctx.quick, ctx.engines + [e for e, where in ctx.partial.items() if "impacts" in where])


def write(ctx):
    runs = [r for r in ctx.all_runs if r.tag.startswith("impact_")]
    return impact_suite.summarize(runs, ctx.out, ctx.fig, ctx.quick)
