"""The software versions and every setting of every engine, as each run recorded them."""
import floedem


def plan(ctx):
    return []


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def write(ctx):
    md = ["## Engines: versions and settings", "",
          "As recorded in the towing runs' root and `/engine` attributes (every setting in force).", ""]
    for e in ctx.engines:
        run = ctx.run(f"towing_{e}")
        with floedem.open(run.out) as f:
            a = f.engine_info
            md += [f"### {e}: {text(f.attrs['engine_version'])}", "",
                   f"floedem {text(f.attrs['floedem_version'])}; forcing terms: {text(f.attrs['forcing_terms'])}.", "",
                   "| setting | value |", "|---|---|"]
            for k in sorted(a.keys()):
                if k != "limitations":
                    md.append(f"| {k} | {text(a[k])} |")
            lim = text(a.get("limitations", "")).strip()
            if lim:
                md += ["", "Limitations: " + "; ".join(lim.splitlines()) + "."]
            md.append("")
    return md, []
