"""One section of a generated Markdown document (docs/performance.md), written by the script that
measures it: the section's lines replace an existing section of the same title (up to the next
"## " heading or the "Notes:" line), else they go in before "Notes:" (or at the end).
bench/performance.py keeps the sections other scripts write, in place."""
import os


def write_section(path, title, section):
    """Writes `section` (lines, its first the "## ..." heading starting with `title`) into `path`
    atomically (a temporary, then a rename)."""
    lines = open(path).read().splitlines() if os.path.exists(path) else []
    start = next((i for i, l in enumerate(lines) if l.startswith(title)), None)
    if start is not None:
        end = next((i for i in range(start + 1, len(lines)) if lines[i].startswith(("## ", "Notes:"))), len(lines))
        lines[start:end] = section
    else:
        at = next((i for i, l in enumerate(lines) if l.startswith("Notes:")), len(lines))
        lines[at:at] = section
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(lines).rstrip("\n") + "\n")
    os.replace(path + ".tmp", path)
