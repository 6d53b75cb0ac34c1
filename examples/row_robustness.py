"""The perception map of the daylight row (issue 37 item 5): today's detectors (colour,
net, net+colour), their stereo localisation of ripe berries and the cane fit, per frame,
over light x camera model x look-alikes x fruit density on fresh seeds, as Ray trials of
``softarm sweep`` (one after another without Ray). The spec is
examples/sweeps/row_robustness.toml; the trials stay in OUT/cells (``--resume`` reuses
them). The table, JSON and picture of docs/perception.md and docs/robustness.md come from::

    MUJOCO_GL=egl python examples/row_robustness.py --docs docs

which writes docs/data/row_robustness.json, docs/img/row_robustness_map.png and the table
between the markers in docs/perception.md.
"""

from __future__ import annotations

import argparse
import json
import re
import shutil
from pathlib import Path

from softarm.sweep.perception_map import markdown_table, run_map, summarise, write_outputs
from softarm.sweep.perception_spec import load_perception_spec

SPEC = Path(__file__).resolve().parent / "sweeps" / "row_robustness.toml"
#: The table's place in docs/perception.md.
BEGIN, END = "<!-- row_robustness table -->", "<!-- end row_robustness table -->"


def _into_docs(docs: Path, out: Path, table: str) -> None:
    shutil.copyfile(out / "row_robustness.json", docs / "data" / "row_robustness.json")
    shutil.copyfile(out / "row_robustness_map.png", docs / "img" / "row_robustness_map.png")
    page = docs / "perception.md"
    text = page.read_text(encoding="utf-8")
    block = f"{BEGIN}\n{table}{END}"
    new, n = re.subn(re.escape(BEGIN) + ".*?" + re.escape(END), lambda _: block, text, flags=re.S)
    if n != 1:
        raise SystemExit(f"{page}: the markers {BEGIN} ... {END} are not there once")
    page.write_text(new, encoding="utf-8")
    print(f"docs: {docs}/data/row_robustness.json, {docs}/img/row_robustness_map.png, {page}")


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(
        description=__doc__.split("\n\n")[0],
        formatter_class=argparse.ArgumentDefaultsHelpFormatter,
    )
    parser.add_argument("--spec", type=Path, default=SPEC, help="perception map spec")
    parser.add_argument("--out", type=Path, default=Path("out/row_robustness"), help="folder")
    parser.add_argument("--cpus", type=int, help="cores of the local Ray (default: all)")
    parser.add_argument("--no-ray", action="store_true", help="run in this process")
    parser.add_argument("--docs", type=Path, help="also update the docs in this folder")
    args = parser.parse_args(argv)
    spec = load_perception_spec(args.spec)
    outcome = run_map(
        spec,
        args.out,
        use_ray=False if args.no_ray else None,
        cpus=args.cpus,
        resume=True,
        on_trial=lambda r: print(
            f"{r['look']}/{r['effects']}/{r['lookalikes']}/{r['fruit']} {r['seed']}: "
            f"{r.get('error') or str(r.get('wall_s')) + ' s'}",
            flush=True,
        ),
    )
    print(f"{outcome.ran} trials run ({outcome.failed} failed), {outcome.skipped} done before, "
          f"{outcome.wall_s:.0f} s on {outcome.cpus:g} CPUs")  # fmt: skip
    doc = summarise(spec, args.out)
    earlier = args.out / "row_robustness.json"
    if outcome.ran == len(spec.trials()):  # the whole map in this call: its cost
        doc["run"] = {"wall_s": outcome.wall_s, "cpus": outcome.cpus, "on_ray": outcome.on_ray}
    elif outcome.ran == 0 and earlier.is_file():  # nothing new: the run that made it
        doc["run"] = json.loads(earlier.read_text()).get("run")
    write_outputs(doc, args.out)
    table = markdown_table(doc)
    print(table)
    if args.docs is not None:
        _into_docs(args.docs, args.out, table)


if __name__ == "__main__":
    main()
