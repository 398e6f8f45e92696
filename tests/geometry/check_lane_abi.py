"""No function of a built library takes a 32-byte vector out of line (geometry/lane_inline.hpp).

The four-lane kernels are built for the x86-64 baseline, AVX2 and AVX-512. A helper that takes
a four-lane vector and is not inlined is compiled for the baseline, which expects the vector in
memory, while an AVX kernel calling it passes it in a ymm register: the helper computes with
whatever memory holds. Nothing fails; forces come out wrong. Every such helper is always
inlined, so the built library holds no function whose own parameters are 32- or 64-byte
vectors. This reads the library's symbols (nm, demangled) and names each one that does.

    check_lane_abi.py NM LIBRARY
"""
import subprocess
import sys

# GCC's vector extension types, demangled: double or int64 lanes, four (32 bytes) or eight.
WIDE = ("double __vector(4)", "long __vector(4)", "double __vector(8)", "long __vector(8)")


def own_parameters(name):
    """The parameter list of the function a demangled symbol names (not its enclosing scopes':
    a lambda's operator() inside a kernel that takes vectors names the kernel's too)."""
    name = name.split(" [clone", 1)[0].rstrip()  # GCC's clones: ".isra.0", ".constprop.0"
    for qualifier in (" const", " volatile", " &&", " &"):
        if name.endswith(qualifier):
            name = name[: -len(qualifier)].rstrip()
    if not name.endswith(")"):
        return ""  # a variable, a vtable, a guard
    depth = 0
    for i in range(len(name) - 1, -1, -1):
        if name[i] == ")":
            depth += 1
        elif name[i] == "(":
            depth -= 1
            if depth == 0:
                return name[i + 1 : -1]
    return ""


def main():
    nm, library = sys.argv[1], sys.argv[2]
    out = subprocess.run([nm, "-C", "--defined-only", library], check=True, capture_output=True, text=True).stdout
    bad = []
    for line in out.splitlines():
        parts = line.split(" ", 2)
        if len(parts) != 3 or parts[1] not in "tTwW":
            continue
        if any(w in own_parameters(parts[2]) for w in WIDE):
            bad.append(parts[2])
    if bad:
        print(f"{library}: {len(bad)} function(s) take a 32-byte vector out of line; an AVX kernel "
              "calling one passes it where the baseline build does not look. Mark each "
              "FLOEDEM_LANES (functions) or FLOEDEM_LANES_LAMBDA (lambdas), geometry/lane_inline.hpp:")
        for name in sorted(set(bad)):
            print("  " + name)
        return 1
    print(f"{library}: no function takes a 32-byte vector out of line")
    return 0


if __name__ == "__main__":
    sys.exit(main())
