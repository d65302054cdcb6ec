"""Reading YAML: CPU time and peak memory of robotspec's reader against ``yaml.load``, one run.

Run: ``python benchmarks/bench_yaml_reading.py [--megabytes 7.6]``. The cases of issue 31: a
10 kB document of nine aliases of nine aliases just under the node cap (990,000 nodes
expanded; it peaked at 230-370 MB when aliases were copied), a 7.6 MB file of short lists with
a syntax error on its last line (parsed twice before: 18 s of CPU), and the same file valid.
The peer is PyYAML's own ``yaml.load`` with the same parser (libyaml's where PyYAML has it),
which shares aliases too but keeps no places. Times are CPU seconds (``time.process_time``),
so another process on the machine does not inflate them; peak memory is tracemalloc's (it
slows both sides alike). Ratios are peer time / robotspec time.
"""

from __future__ import annotations

import argparse
import os
import random
import time
import tracemalloc
from collections.abc import Callable

from rows import Row, add_json_flag, print_rows


def near_cap() -> str:
    lines = ["a0: &a0 [x, x, x, x, x, x, x, x, x]"]
    lines += [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 6)]
    lines.append("b: [" + ", ".join(["*a4"] * 4 + ["*a3"] * 6) + "]")
    text = "\n".join(lines) + "\n"
    return text + "# " + "p" * (10_000 - len(text) - 3) + "\n"


def big(megabytes: float, *, broken: bool) -> str:
    rnd = random.Random(1)
    parts, size, i = [], 0, 0
    while size < megabytes * 1e6:
        line = f"k{i}: [{rnd.random():.6f}, {rnd.random():.6f}, name_{i}]\n"
        parts.append(line)
        size += len(line)
        i += 1
    if broken:
        parts.append("oops: : [\n")
    return "".join(parts)


def measure(fn: Callable[[], object]) -> tuple[float, float]:
    """(CPU seconds, peak traced MB) of one call; an exception is the expected outcome too."""
    t = time.process_time()
    try:
        fn()
    except Exception:  # noqa: BLE001 - a syntax error is the case measured
        pass
    cpu = time.process_time() - t
    tracemalloc.start()
    try:
        fn()
    except Exception:  # noqa: BLE001
        pass
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    return cpu, peak / 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--megabytes", type=float, default=7.6, help="size of the big files")
    add_json_flag(parser)
    args = parser.parse_args()
    os.environ["ROBOTSPEC_MAX_YAML_ALIAS_NODES"] = "1e9"  # the node cap alone, as in the issue

    import yaml

    from robotspec.files.limits import limits
    from robotspec.files.yamlio import _parser, load_yaml_text

    loader = _parser(limits())
    cases = [
        ("10 kB, 990,000 nodes through aliases", near_cap()),
        (f"{args.megabytes} MB, syntax error at the end", big(args.megabytes, broken=True)),
        (f"{args.megabytes} MB, valid", big(args.megabytes, broken=False)),
    ]
    rows = []
    for what, text in cases:
        ours, ours_mb = measure(lambda text=text: load_yaml_text(text, "bench.yaml"))
        peer, peer_mb = measure(lambda text=text: yaml.load(text, Loader=loader))
        rows.append(
            Row(
                f"{what}: {ours_mb:.0f} MB",
                ours,
                f"yaml.load ({loader.__mro__[1].__name__}): {peer_mb:.0f} MB",
                peer,
            )
        )
    print_rows(rows, args.json, width=52, peer_width=36)


if __name__ == "__main__":
    main()
