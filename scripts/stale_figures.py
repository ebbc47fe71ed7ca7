#!/usr/bin/env python3
"""Figures in the READMEs and docs that the regenerated results no longer hold.

    python3 scripts/stale_figures.py [REV]

After `bash results/regenerate.sh` (whole or in part), lists every decimal figure quoted in
README.md, docs/*.md and results/**/README.md that some results file held at REV (default
HEAD: the results before the regeneration, as committed) and none holds now: a figure copied
from a results file that changed. A results number counts in each form it may be quoted in
(as written, and rounded to 0 to 3 decimals). A README under results/ is held against the
results files of its own folder, the other docs against all. Figures derived by hand (ratios, sums) are not
seen: the list is where to start, not a proof that the rest is current. Exits 1 when it lists
any.
"""

import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULT_SUFFIXES = {".json", ".md", ".csv", ".txt", ".tex"}
NUMBER = re.compile(r"-?\d+(?:\.\d+)?(?:[eE]-?\d+)?")
FIGURE = re.compile(r"(?<![\w.])\d+\.\d+(?![\w.])")


def git(*args):
    return subprocess.run(
        ["git", "-C", str(ROOT), *args], check=True, capture_output=True, text=True
    ).stdout


def forms(text):
    """Every way the numbers of `text` may be quoted."""
    out = set()
    for token in NUMBER.findall(text):
        out.add(token.lstrip("-"))
        try:
            x = abs(float(token))
        except ValueError:
            continue
        for d in range(4):
            out.add(f"{x:.{d}f}")
    return out


def results_files(paths):
    return [
        p
        for p in paths
        if p.startswith("results/")
        and Path(p).suffix in RESULT_SUFFIXES
        and not p.endswith("README.md")
    ]


def main():
    rev = sys.argv[1] if len(sys.argv) > 1 else "HEAD"
    if len(sys.argv) > 2 or rev in ("-h", "--help"):
        print(__doc__.strip())
        return 2
    old = {}
    for path in results_files(git("ls-tree", "-r", "--name-only", rev, "results").split()):
        old[path] = forms(git("show", f"{rev}:{path}"))
    tracked = git("ls-files", "results").split()
    untracked = git("ls-files", "--others", "--exclude-standard", "results").split()
    new = {}
    for path in results_files(tracked + untracked):
        file = ROOT / path
        if file.exists():
            new[path] = forms(file.read_text(errors="replace"))

    def within(files, folder):
        return set().union(*(f for p, f in files.items() if p.startswith(folder)))

    docs = ["README.md", *git("ls-files", "docs/*.md").split()]
    docs += [p for p in tracked if p.endswith("README.md")]
    stale = 0
    for doc in docs:
        folder = str(Path(doc).parent) + "/" if doc.startswith("results/") else "results/"
        old_forms, new_forms = within(old, folder), within(new, folder)
        for number, line in enumerate((ROOT / doc).read_text().splitlines(), 1):
            figures = [f for f in FIGURE.findall(line) if f in old_forms and f not in new_forms]
            if figures:
                stale += len(figures)
                print(f"{doc}:{number}: {', '.join(figures)}: {line.strip()[:120]}")
    print(f"{stale} figures in the docs that results at {rev} held and the results now do not")
    return 1 if stale else 0


if __name__ == "__main__":
    sys.exit(main())
