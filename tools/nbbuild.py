"""Write a notebook from a plain-text cell list (``# %% [markdown]`` / ``# %%`` markers).

Usage: python tools/nbbuild.py book/src/ch01_data.py book/ch01_data.ipynb
The .py source is the one to edit; the .ipynb is what the book executes.
"""
import sys

import nbformat


def parse(text: str):
    cells, kind, buf = [], None, []

    def flush():
        if kind is None:
            return
        src = "\n".join(buf).strip("\n")
        if kind == "md":
            src = "\n".join(l[2:] if l.startswith("# ") else l.lstrip("#") for l in src.splitlines())
            cells.append(nbformat.v4.new_markdown_cell(src))
        else:
            cells.append(nbformat.v4.new_code_cell(src))

    for line in text.splitlines():
        if line.startswith("# %% [markdown]"):
            flush(); kind, buf = "md", []
        elif line.startswith("# %%"):
            flush(); kind, buf = "code", []
        else:
            buf.append(line)
    flush()
    return cells


if __name__ == "__main__":
    src, dst = sys.argv[1], sys.argv[2]
    nb = nbformat.v4.new_notebook()
    nb.cells = parse(open(src).read())
    nb.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
    nb.metadata["language_info"] = {"name": "python"}
    nbformat.write(nb, dst)
    print(f"wrote {dst} ({len(nb.cells)} cells)")
