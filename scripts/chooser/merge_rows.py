#!/usr/bin/env python3
"""The shipped model's rows with another run's hybrid+pt rows added (issue 40, session 8):

    python3 scripts/chooser/merge_rows.py OLD.jsonl NEW.jsonl > MERGED.jsonl

For each scene of OLD (the rows the shipped model was fitted on) that NEW also holds, NEW's
hybrid+pt rows (which OLD's bench did not run) are added. Their FLIP is NEW's (the ꟻLIP of a
row does not depend on the load: the path tracer's at equal spp is the same in both runs,
median ratio 1.002 over s5/s8); their ms are rescaled to OLD's run by the median over the
scene's path-tracer rows present in both of OLD's ms over NEW's (the two runs' loads differ,
and not uniformly: per scene). OLD's rows are kept as they are, so a model fitted on the
result with --guided off is OLD's model, and with --guided it adds the hybrid+pt candidates.
"""
import json
import sys

PT = {"pt", "pt+atrous", "pt+denoise", "pt-low", "pt-low+atrous"}
GUIDED = "hybrid+pt"


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    new = {}
    for line in open(sys.argv[2]):
        if line.startswith("{"):
            d = json.loads(line)
            new[d["scene"].rsplit("/", 1)[-1]] = d
    for line in open(sys.argv[1]):
        if not line.startswith("{"):
            continue
        d = json.loads(line)
        n = new.get(d["scene"].rsplit("/", 1)[-1])
        if n is not None and not any(r["family"] == GUIDED for r in d["rows"]):
            old_ms = {(r["family"], r["name"]): r["ms"] for r in d["rows"] if r["family"] in PT}
            ratios = sorted(old_ms[(r["family"], r["name"])] / r["ms"] for r in n["rows"]
                            if (r["family"], r["name"]) in old_ms and r["ms"] > 0)
            scale = ratios[len(ratios) // 2] if ratios else 1.0
            d["rows"] += [dict(r, ms=r["ms"] * scale) for r in n["rows"] if r["family"] == GUIDED]
            count = sum(r["family"] == GUIDED for r in n["rows"])
            print("merge_rows.py: %s: %d hybrid+pt rows, ms x %.3f" % (
                d["scene"].rsplit("/", 1)[-1], count, scale), file=sys.stderr)
        print(json.dumps(d))


if __name__ == "__main__":
    sys.exit(main())
