#!/usr/bin/env python3
"""Fills the generated blocks of the technique pages (docs/*.md) from the code's tables and
the bench JSON, so that no page keeps a hand-typed copy of a default or a measured figure.

A page asks for a block with a marker line and gets its body between that line and
`<!-- end generated -->`:

  <!-- generated: knobs FAMILY[,FAMILY...] -->   the knob table's rows of those families
                                                 (the `<a id="FAMILY">` sections of
                                                 `drift --knobs-markdown`)
  <!-- generated: options COMMAND REGEX -->      the option-table rows of `drift COMMAND`
                                                 (docs/reference/cli.md) whose option matches
                                                 REGEX: a technique that is an option, not a
                                                 knob family (glare, SIR, temporal reuse, ...)
  <!-- generated: frontier REGEX -->             per scene of the bench JSON, the hybrid row
                                                 of least FLIP whose name matches REGEX, and
                                                 the best path-tracer row at most as slow

usage: gen-technique-blocks.py KNOBS_MD CLI_MD FRONTIER_JSONL DOCS_DIR OUT_DIR
Pages with blocks are written to OUT_DIR (DOCS_DIR itself to update them in place).
Run by scripts/gen-reference.sh; tests/cli/test_reference_docs.sh fails while a page is stale.
"""
import json
import os
import re
import sys

MARK = re.compile(r"^<!-- generated: (knobs|options|frontier) (.+?) -->$")
END = "<!-- end generated -->"
PT_FAMILIES = ("pt", "pt+atrous", "pt+denoise", "pt-low", "pt-low+atrous")


def knob_sections(knobs_md):
    """{family id: the section's lines after its heading (the table)}"""
    sections, current = {}, None
    for line in open(knobs_md, encoding="utf-8"):
        m = re.match(r'^<a id="([^"]+)"></a>$', line.strip())
        if m:
            current = m.group(1)
            sections[current] = []
        elif current is not None:
            sections[current].append(line.rstrip("\n"))
    for family, lines in sections.items():
        # Drop the heading and the blank lines around the table.
        body = [l for l in lines if not l.startswith("## ")]
        while body and not body[0].strip():
            body.pop(0)
        while body and not body[-1].strip():
            body.pop()
        sections[family] = body
    return sections


def knobs_block(arg, sections, source):
    out = []
    for family in arg.split(","):
        if family not in sections:
            sys.exit(f"{source}: no knob family '{family}' in the knob table")
        out += sections[family] + [""]
    out.append(
        "Generated from the knob table (`drift --knobs-markdown`); the whole table is in the "
        "[knob reference](reference/knobs.md)."
    )
    return out


def command_rows(cli_md):
    """{command: [option-table rows]} of `drift --help-markdown` (the `## drift COMMAND` sections)"""
    commands, current = {}, None
    for line in open(cli_md, encoding="utf-8"):
        line = line.rstrip("\n")
        if line.startswith("## drift"):
            current = line[len("## drift"):].strip() or "drift"
            commands[current] = []
        elif current and line.startswith("| `--"):
            commands[current].append(line)
    return commands


def options_block(arg, commands, source):
    command, _, regex = arg.partition(" ")
    if command not in commands:
        sys.exit(f"{source}: no command 'drift {command}' in the CLI reference")
    pattern = re.compile(regex)
    rows = [r for r in commands[command] if pattern.search(r.split("`")[1])]
    if not rows:
        sys.exit(f"{source}: no option of drift {command} matches /{regex}/")
    return (
        ["| option | argument | description |", "|---|---|---|"]
        + rows
        + [
            "",
            f"Generated from the option table of `drift {command}` (`--help`); all its options "
            f"are in the [command-line reference](reference/cli.md#drift-{command.replace(' ', '-')}).",
        ]
    )


def frontier_block(arg, runs, rows_path, source):
    pattern = re.compile(arg)
    out = [
        "| scene | size | best matching row | ms | ꟻLIP | best path tracer at most as slow | ms | ꟻLIP |",
        "|---|---|---|---|---|---|---|---|",
    ]
    found = 0
    for run in runs:
        scene = os.path.splitext(os.path.basename(run["scene"]))[0]
        rows = [r for r in run["rows"] if r["family"] == "hybrid" and pattern.search(r["name"])]
        if not rows:
            continue
        best = min(rows, key=lambda r: (r["flip"], r["ms"]))
        pts = [r for r in run["rows"] if r["family"] in PT_FAMILIES and r["ms"] <= best["ms"]]
        pt = min(pts, key=lambda r: (r["flip"], r["ms"])) if pts else None
        pt_cells = (
            f"{pt['family']} {pt['name']} | {pt['ms']:.0f} | {pt['flip']:.3f}"
            if pt
            else "none as fast | | "
        )
        out.append(
            f"| {scene} | {run['size']}² | {best['name']} | {best['ms']:.0f} | "
            f"{best['flip']:.3f} | {pt_cells} |"
        )
        found += 1
    if not found:
        sys.exit(f"{source}: no hybrid row of {rows_path} matches /{arg}/")
    out += [
        "",
        f"Generated from the bench JSON `{rows_path}` (`drift bench frontier --corpus ... "
        "--json` on the shared 2-core build machine, issue 40; ms are wall time, ꟻLIP against "
        "the scene's path-traced reference). A row's ms depend on the machine; compare rows "
        "of one table.",
    ]
    return out


def main():
    knobs_md, cli_md, rows_path, docs, out_dir = sys.argv[1:6]
    sections = knob_sections(knobs_md)
    commands = command_rows(cli_md)
    runs = [json.loads(l) for l in open(rows_path, encoding="utf-8") if l.strip()]
    rows_name = os.path.relpath(rows_path, os.path.dirname(os.path.abspath(docs)))
    os.makedirs(out_dir, exist_ok=True)
    for name in sorted(os.listdir(docs)):
        if not name.endswith(".md"):
            continue
        path = os.path.join(docs, name)
        lines = open(path, encoding="utf-8").read().split("\n")
        if not any(MARK.match(l) for l in lines):
            continue
        result, i = [], 0
        while i < len(lines):
            line = lines[i]
            result.append(line)
            m = MARK.match(line)
            i += 1
            if not m:
                continue
            try:
                end = lines.index(END, i)
            except ValueError:
                sys.exit(f"{path}:{i}: '{line}' has no '{END}'")
            source = f"{path}:{i}"
            if m.group(1) == "knobs":
                result += knobs_block(m.group(2), sections, source)
            elif m.group(1) == "options":
                result += options_block(m.group(2), commands, source)
            else:
                result += frontier_block(m.group(2), runs, rows_name, source)
            result.append(END)
            i = end + 1
        with open(os.path.join(out_dir, name), "w", encoding="utf-8") as f:
            f.write("\n".join(result))


if __name__ == "__main__":
    main()
