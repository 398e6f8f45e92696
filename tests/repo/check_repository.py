#!/usr/bin/env python3
"""Checks that the repository explains itself (run by ctest, one check per test):

  outside     no tracked file points outside the repository (a clone has nothing beside it)
  stages      docs/architecture.md's stage table names the code's stages, in order
  performance docs/performance.md is what reports/performance_doc.py makes of the committed CSVs
  readme      README.md is a map of at most 250 lines, and every relative link in it and in
              docs/ names a file or folder of the repository

usage: check_repository.py CHECK --root DIR [--floedem build/floedem]
"""
import argparse
import os
import re
import subprocess
import sys

# Assembled so that this file does not match its own pattern.
OUTSIDE = ".." + "/shared"
README_MOST = 250


def tracked(root):
    """The files git tracks, or every file of the tree outside a checkout (build folders left out)."""
    try:
        out = subprocess.run(["git", "-C", root, "ls-files", "-z"], capture_output=True, check=True).stdout
        names = [n for n in out.decode().split("\0") if n]
        if names:
            return names
    except (OSError, subprocess.CalledProcessError):
        pass
    names = []
    for d, dirs, files in os.walk(root):
        dirs[:] = [x for x in dirs if not x.startswith(("build", ".", "results"))]
        names += [os.path.relpath(os.path.join(d, f), root) for f in files]
    return names


def check_outside(a):
    bad = []
    for name in tracked(a.root):
        path = os.path.join(a.root, name)
        try:
            with open(path, "rb") as f:
                data = f.read()
        except OSError:
            continue
        if b"\0" in data[:4096]:
            continue  # binary (figures)
        for k, line in enumerate(data.decode("utf-8", "replace").splitlines(), 1):
            if OUTSIDE in line:
                bad.append(f"{name}:{k}: {line.strip()[:100]}")
    for b in bad:
        print(f"points outside the repository: {b}")
    return not bad


def check_stages(a):
    out = subprocess.run([a.floedem, "stages"], capture_output=True, text=True, check=True).stdout
    code = [line.split("\t")[0] for line in out.splitlines() if line]
    with open(os.path.join(a.root, "docs", "architecture.md")) as f:
        text = f.read()
    section = text.split("## The step's stages", 1)[1].split("\n## ", 1)[0]
    doc = re.findall(r"^\| `([a-z_]+)` \|", section, re.M)
    if doc != code:
        print(f"docs/architecture.md lists the stages {doc}; `floedem stages` gives {code}")
        return False
    return True


def check_performance(a):
    script = os.path.join(a.root, "reports", "performance_doc.py")
    return subprocess.run([sys.executable, script, "--check"]).returncode == 0


def check_readme(a):
    ok = True
    with open(os.path.join(a.root, "README.md")) as f:
        lines = f.read().splitlines()
    if len(lines) > README_MOST:
        print(f"README.md has {len(lines)} lines; at most {README_MOST} (the reference belongs in docs/)")
        ok = False
    pages = ["README.md"] + [os.path.join("docs", n) for n in sorted(os.listdir(os.path.join(a.root, "docs")))
                             if n.endswith(".md")]
    for page in pages:
        with open(os.path.join(a.root, page)) as f:
            text = f.read()
        for target in re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", text):
            if re.match(r"[a-z]+:", target):
                continue  # a URL
            path = os.path.normpath(os.path.join(a.root, os.path.dirname(page), target))
            if not os.path.exists(path):
                print(f"{page}: link to {target}: no such file in the repository")
                ok = False
    return ok


CHECKS = {"outside": check_outside, "stages": check_stages, "performance": check_performance, "readme": check_readme}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("check", choices=sorted(CHECKS))
    ap.add_argument("--root", required=True)
    ap.add_argument("--floedem", default="")
    a = ap.parse_args()
    ok = CHECKS[a.check](a)
    print(f"{a.check}: {'ok' if ok else 'FAILED'}")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
