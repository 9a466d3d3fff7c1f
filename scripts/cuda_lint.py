#!/usr/bin/env python3
"""Checks C++ sources for code that compiles for OpenMP but not for CUDA (or not correctly on a GPU).

    python3 scripts/cuda_lint.py FILE...        # exit 1 and one line per finding if any

Rules (each found by nvcc in session 14 or named in DEVELOPERS.md; docs/PERFORMANCE.md, "Backends"):
  device-std      std:: inside a KOKKOS_LAMBDA / KOKKOS_INLINE_FUNCTION / KOKKOS_FUNCTION body
  device-throw    throw inside such a body
  device-virtual  virtual inside such a body
  lambda-this     this inside a KOKKOS_LAMBDA (a host pointer on a GPU)
  lambda-constexpr-if   if constexpr inside a KOKKOS_LAMBDA (nvcc: no first capture in a constexpr-if)
  lambda-in-test  KOKKOS_LAMBDA inside a gtest TEST body (a private member function: nvcc rejects it)
A heuristic, not a compiler: scripts/cuda_check.sh compiles everything with nvcc.
"""
import re
import sys


def strip(text):
    """Comments and string/char literals blanked out (same length, newlines kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif c in "\"'":
            j = i + 1
            while j < n and text[j] != c:
                j += 2 if text[j] == "\\" else 1
            out.append(c + " " * (min(j, n - 1) - i - 1) + c)
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def body_after(code, start):
    """(begin, end) of the brace block that follows start, or None if a ';' comes first (a declaration)."""
    depth_paren = 0
    i = start
    while i < len(code):
        c = code[i]
        if c == "(":
            depth_paren += 1
        elif c == ")":
            depth_paren -= 1
        elif c == ";" and depth_paren <= 0:
            return None
        elif c == "{" and depth_paren <= 0:
            break
        i += 1
    else:
        return None
    depth, j = 0, i
    while j < len(code):
        if code[j] == "{":
            depth += 1
        elif code[j] == "}":
            depth -= 1
            if depth == 0:
                return i, j
        j += 1
    return None


DEVICE = re.compile(r"\b(KOKKOS_LAMBDA|KOKKOS_INLINE_FUNCTION|KOKKOS_FUNCTION|KOKKOS_CLASS_LAMBDA)\b")
RULES_ALL = [("device-std", re.compile(r"\bstd::")), ("device-throw", re.compile(r"\bthrow\b")),
             ("device-virtual", re.compile(r"\bvirtual\b"))]
RULES_LAMBDA = [("lambda-this", re.compile(r"\bthis\b")),
                ("lambda-constexpr-if", re.compile(r"\bif\s+constexpr\b"))]
TEST = re.compile(r"\bTEST(_F|_P)?\s*\(")


def check(path):
    text = open(path, errors="replace").read()
    code = strip(text)
    line = lambda pos: code.count("\n", 0, pos) + 1  # noqa: E731
    found = set()
    for m in DEVICE.finditer(code):
        block = body_after(code, m.end())
        if not block:
            continue
        b, e = block
        rules = RULES_ALL + (RULES_LAMBDA if "LAMBDA" in m.group(1) else [])
        for name, rx in rules:
            for r in rx.finditer(code, b, e):
                found.add((line(r.start()), name, code[r.start():r.end()]))
    for m in TEST.finditer(code):
        block = body_after(code, code.find(")", m.end()) + 1)
        if not block:
            continue
        for r in re.finditer(r"\bKOKKOS_(CLASS_)?LAMBDA\b", code[block[0]:block[1]]):
            found.add((line(block[0] + r.start()), "lambda-in-test", "KOKKOS_LAMBDA"))
    return [f"{path}:{ln}: {name}: {what}" for ln, name, what in sorted(found)]


def main(argv):
    if len(argv) < 2 or any(a in ("-h", "--help") for a in argv[1:]):
        print(__doc__.strip(), file=sys.stdout if len(argv) >= 2 else sys.stderr)
        return 0 if len(argv) >= 2 else 2
    findings = []
    for path in argv[1:]:
        findings += check(path)
    for f in findings:
        print(f)
    print(f"cuda_lint: {len(findings)} finding(s) in {len(argv) - 1} file(s)", file=sys.stderr)
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
