"""Do two trees of generated C headers compute the same bits?

    python bench/same_bits_c.py OLD_DIR NEW_DIR [--vectors 20000] [--flags "-O2 -ffp-contract=off"]

For every header symrot_NAME.h found in both folders, one driver calls every public single-call
function of the header (both precisions; the ``_batch`` kernels on the same vectors) on the same
inputs: random vectors of every length up to the validity edge and past it, tiny ones down to
subnormals, zeros, inf and NaN. Every NaN counts as one value (C leaves the sign and payload of a
NaN that an operation returns to the order of the operations). The driver is compiled once against
each folder (gcc, the flags given) and its outputs are compared bit for bit; where they differ, by
how many representable numbers. A refactor of the C writer that claims "the same
statements, shared" is checked with this.
"""

from __future__ import annotations

import argparse
import re
import subprocess
import sys
import tempfile
from pathlib import Path

SIGNATURE = re.compile(r"^static inline (void|int|double|float) (symrot_[a-z0-9_]+?)\((.*)\)$", re.M)
ARRAY = re.compile(r"(const )?(double|float) (\w+)\[(\d+)\]")


def calls(header: Path) -> list[str]:
    """C statements that call each public function of ``header`` on input k and print its outputs."""
    name = header.stem  # symrot_NAME
    lines = []
    for returned, function, parameters in SIGNATURE.findall(header.read_text(encoding="utf-8")):
        if function.startswith(f"{name}__"):
            continue  # internal helpers: reached through the public functions
        if "size_t n" in parameters:
            ctype = "double" if "double" in parameters else "float"
            width = 9  # the batch kernels are those of the matrix functions
            source = "P" if ctype == "double" else "PF"
            lines.append(f"    {{ static {ctype} out[9 * COUNT]; {function}(COUNT, {source}, out); "
                         f"show_{ctype}(\"{function}\", out, {width} * COUNT); }}")
            continue
        arrays = ARRAY.findall(parameters)
        if not arrays or len(arrays) != parameters.count(",") + 1:
            continue  # another shape (quaternion scalars): covered through its public callers
        ctype = arrays[0][1]
        arguments, outputs = [], []
        inputs = 0
        for const, _, array, size in arrays:
            if const:
                source = "P" if ctype == "double" else "PF"
                arguments.append(f"{source} + 3 * ((k + {inputs * 7919}) % COUNT)")
                inputs += 1
            else:
                arguments.append(array)
                outputs.append((array, int(size)))
        declarations = " ".join(f"{ctype} {array}[{size}];" for array, size in outputs)
        call = f"{function}({', '.join(arguments)})"
        if returned != "void":
            call = f"{{ {returned} r = {call}; show_{returned}(\"{function}\", &r, 1); }}"
        else:
            call += ";"
        shows = " ".join(f"show_{ctype}(\"{function}\", {array}, {size});" for array, size in outputs)
        lines.append(f"    for (k = 0; k < COUNT; ++k) {{ {declarations} {call} {shows} }}")
    return lines


DRIVER = """#include <stdio.h>
#include <string.h>
#include <math.h>
#include "{header}"
#define COUNT {count}
static double P[3 * COUNT];
static float PF[3 * COUNT];
static void show_double(const char *name, const double *v, size_t n) {{
    size_t i; unsigned long long bits;
    for (i = 0; i < n; ++i) {{
        memcpy(&bits, v + i, 8);
        if (v[i] != v[i]) printf("%s nan\\n", name); else printf("%s %llx\\n", name, bits);
    }}
}}
static void show_float(const char *name, const float *v, size_t n) {{
    size_t i; unsigned int bits;
    for (i = 0; i < n; ++i) {{
        memcpy(&bits, v + i, 4);
        if (v[i] != v[i]) printf("%s nan\\n", name); else printf("%s %x\\n", name, bits);
    }}
}}
static void show_int(const char *name, const int *v, size_t n) {{
    size_t i;
    for (i = 0; i < n; ++i) printf("%s %d\\n", name, v[i]);
}}
int main(void) {{
    size_t k;
    unsigned long long state = 88172645463325252ULL;
    for (k = 0; k < 3 * COUNT; ++k) {{
        double u, scale;
        state ^= state << 13; state ^= state >> 7; state ^= state << 17;
        u = (double)(state >> 11) / 9007199254740992.0 * 2.0 - 1.0;
        scale = (k / 3) % 5 == 0 ? ldexp(1.0, -(int)((state >> 3) % 1080)) : {edge} * 1.2;
        P[k] = u * scale;
    }}
    P[0] = P[1] = P[2] = 0.0;
    P[3] = INFINITY; P[7] = NAN; P[9] = -0.0;
    for (k = 0; k < 3 * COUNT; ++k) PF[k] = (float)P[k];
{calls}
    return 0;
}}
"""


def edge(header: Path) -> float:
    """|p| at the validity edge from the header's comment (a large number where p is unbounded)."""
    match = re.search(r"Valid for \|p\| < ([0-9.e+]+)", header.read_text(encoding="utf-8"))
    return float(match[1]) if match else 1e3


def outputs(folder: Path, header: Path, count: int, flags: list[str], work: Path) -> bytes:
    source = work / f"{header.stem}.c"
    source.write_text(DRIVER.format(header=header.name, count=count, edge=repr(edge(header)),
                                    calls="\n".join(calls(header))), encoding="utf-8")
    binary = work / f"{header.stem}_{folder.name}"
    subprocess.run(["gcc", "-std=c99", *flags, "-I", str(folder), str(source), "-o", str(binary), "-lm"],
                   check=True)
    return subprocess.run([str(binary)], check=True, capture_output=True).stdout


def largest_step(differing: list[tuple[bytes, bytes]]) -> str:
    """The largest distance between two outputs in representable numbers (ulps where they are
    close), ``nan`` where one of them is NaN and the other is not."""
    largest = 0
    for a, b in differing:
        name, bits = a.split()[0], [line.split()[1] for line in (a, b)]
        if b"nan" in bits:
            return "nan"
        ordered = []
        for word in bits:
            value = int(word, 16)
            sign = 1 << (31 if name.endswith((b"_f", b"_f_batch")) else 63)
            ordered.append(-(value - sign) if value & sign else value)  # monotone in the number
        largest = max(largest, abs(ordered[0] - ordered[1]))
    return str(largest)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old", type=Path)
    parser.add_argument("new", type=Path)
    parser.add_argument("--vectors", type=int, default=20000)
    parser.add_argument("--flags", default="-O2 -ffp-contract=off")
    args = parser.parse_args()
    same = total = 0
    with tempfile.TemporaryDirectory() as directory:
        work = Path(directory)
        for header in sorted(args.new.glob("symrot_*.h")):
            old = args.old / header.name
            if not old.exists():
                continue
            before = outputs(args.old, old, args.vectors, args.flags.split(), work).splitlines()
            after = outputs(args.new, header, args.vectors, args.flags.split(), work).splitlines()
            equal = sum(a == b for a, b in zip(before, after, strict=False))
            if len(before) != len(after) or equal != len(after):
                differing = [(a, b) for a, b in zip(before, after, strict=False) if a != b]
                functions = sorted({b.split()[0].decode() for _, b in differing})
                print(f"{header.name}: {len(after) - equal} of {len(after)} outputs differ "
                      f"({len(before)} before), by up to {largest_step(differing)} steps of the "
                      f"format, in {', '.join(functions)}")
            same += equal
            total += max(len(before), len(after))
    print(f"{same} of {total} outputs have the same bits ({args.flags}, {args.vectors} vectors a function)")
    return 0 if same == total else 1


if __name__ == "__main__":
    sys.exit(main())
