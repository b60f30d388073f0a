#!/usr/bin/env python3
"""No function over MAX_LINES lines outside the tests: the C++/CUDA sources (cpp/, bindings/, bench/,
fuzz/) and the Python (python/, scripts/, figures/). Prints each longer function as `path:line: name is N
lines` and exits 1 when one is found that the allow-list does not name. Part of
scripts/check_format.sh (CI).

    python scripts/check_function_length.py [--max-lines 80] [--allow scripts/function_length_allow.txt]

How a function is measured:
- Python: every `def` (nested ones too, each on its own), from its `def` line to its last line
  (the ast's end_lineno - lineno + 1; decorators not counted).
- C++: a scan of the text with comments, string and character literals and preprocessor lines
  blanked out, matching braces. A `{` at namespace or class scope opens a function body when the
  text before it (since the last `;`, `{` or `}`) holds a parameter list and no `=` outside
  parentheses (a variable's initializer); the function runs from the first line of that text to
  the line of the matching `}`. Lambdas and local classes count as part of their function.

Limits of the C++ scan (it is no parser): a macro that expands to an opening or closing brace
confuses the matching; a namespace-scope variable initialised with `Type name{...}` after a
parenthesised expression may be taken for a function; the name reported is the qualified
identifier before the first top-level `(`, which for an operator or a macro-made function is
approximate. The allow-list names functions as `path:name` (one a line, `#` starts a comment).
"""

from __future__ import annotations

import argparse
import ast
import re
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MAX_LINES = 80
CPP_ROOTS = ("cpp", "bindings", "bench", "fuzz")
PY_ROOTS = ("python", "scripts", "figures")
CPP_SUFFIXES = (".cpp", ".hpp", ".cu", ".cuh", ".h", ".cc")
SCOPE_KEYWORDS = ("namespace", "class", "struct", "union", "extern")
_NAME = re.compile(r"((?:[A-Za-z_~][A-Za-z_0-9]*\s*(?:<[^()]*>)?\s*::\s*)*~?[A-Za-z_][A-Za-z_0-9]*)\s*$")


def blank_cpp(text: str) -> str:
    """`text` with comments, string and character literals and preprocessor lines replaced by spaces
    (newlines kept, so line numbers still hold)."""
    out = list(text)
    i, n = 0, len(text)
    line_start = True

    def blank(a: int, b: int) -> None:
        for k in range(a, min(b, n)):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = text[i]
        if line_start and c == "#":
            j = i
            while j < n and not (text[j] == "\n" and text[j - 1] != "\\"):
                j += 1
            blank(i, j)
            i = j
            continue
        if c == "\n":
            line_start = True
            i += 1
            continue
        if not c.isspace():
            line_start = False
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            blank(i, j)
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            blank(i, j)
            i = j
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            open_paren = text.find("(", i + 2)
            delim = text[i + 2 : open_paren]
            j = text.find(")" + delim + '"', open_paren)
            j = n if j < 0 else j + len(delim) + 2
            blank(i, j)
            i = j
        elif c == '"' or (c == "'" and not (i > 0 and text[i - 1].isalnum() and i + 1 < n and text[i + 1].isalnum())):
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            blank(i, j + 1)
            i = j + 1
        else:
            i += 1
    return "".join(out)


def _is_function_header(header: str) -> bool:
    """Whether the text before a `{` at namespace or class scope is a function's signature."""
    h = header.strip()
    if not h or "(" not in h:
        return False
    first = re.match(r"[A-Za-z_]+", re.sub(r"^template\s*<.*?>\s*", "", h, flags=re.S))
    if first and first.group(0) in SCOPE_KEYWORDS + ("enum",):
        return False
    depth = 0
    for k, ch in enumerate(h):
        if ch in "([":
            depth += 1
        elif ch in ")]":
            depth -= 1
        elif ch == "=" and depth == 0:
            before = h[:k].rstrip()
            if not re.search(r"operator\s*[=!<>+\-*/%&|^]*$", before) and not h[k + 1 : k + 2] == "=":
                return False
    return True


def _function_name(header: str) -> str:
    """The qualified name before the first top-level `(` of a signature."""
    h = re.sub(r"\s+", " ", header.strip())
    op = re.search(r"((?:\w+::)*operator\s*(?:\(\)|[^\s(]+))\s*\(", h)
    if op:
        return op.group(1).replace(" ", "")
    angle = 0
    for k, ch in enumerate(h):
        if ch == "<":
            angle += 1
        elif ch == ">":
            angle = max(0, angle - 1)
        elif ch == "(" and angle == 0:
            m = _NAME.search(h[:k])
            return re.sub(r"\s+", "", m.group(1)) if m else "?"
    return "?"


def _inside_body(stack: list[tuple[str, str, int]]) -> bool:
    """Whether the scan is inside a function body or an initializer (not only namespaces and classes)."""
    return any(kind != "scope" for kind, _, _ in stack)


def cpp_functions(text: str) -> list[tuple[str, int, int]]:
    """(name, first line, line count) of every function body in C++ source `text`."""
    code = blank_cpp(text)
    found = []
    stack: list[tuple[str, str, int]] = []  # (kind: scope|function|other, name, first line)
    segment_start = 0
    in_init_list = False
    line_of = [0] * (len(code) + 1)
    line = 1
    for k, ch in enumerate(code):
        line_of[k] = line
        if ch == "\n":
            line += 1
    for k, ch in enumerate(code):
        if ch == "{":
            header = code[segment_start:k]
            prev = header.rstrip()[-1:] if header.strip() else ""
            if _inside_body(stack):
                stack.append(("other", "", 0))
            elif in_init_list and (prev.isalnum() or prev == "_"):
                stack.append(("other", "", 0))  # a member's braced initializer
                continue
            elif _is_function_header(header):
                start = segment_start + (len(header) - len(header.lstrip()))
                stack.append(("function", _function_name(header), line_of[start]))
            else:
                kind = (
                    "scope"
                    if re.match(r"\s*(template\s*<.*?>\s*)?(namespace|class|struct|union|extern)\b", header, re.S)
                    else "other"
                )
                stack.append((kind, "", 0))
            in_init_list = False
            segment_start = k + 1
        elif ch == "}":
            if stack:
                kind, name, first = stack.pop()
                if kind == "function":
                    found.append((name, first, line_of[k] - first + 1))
            if not in_init_list:
                segment_start = k + 1
        elif ch == ";":
            segment_start = k + 1
            in_init_list = False
        elif ch == ":" and not _inside_body(stack) and code[k + 1 : k + 2] != ":" and code[k - 1 : k] != ":":
            before = code[segment_start:k].rstrip()
            if re.search(r"\b(public|protected|private)$", before):
                segment_start = k + 1  # an access label is no part of the next signature
            elif before.endswith(")"):
                in_init_list = True  # a constructor's member initializers follow
    return found


def python_functions(text: str) -> list[tuple[str, int, int]]:
    """(name, first line, line count) of every def in Python source `text`."""
    found = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            found.append((node.name, node.lineno, node.end_lineno - node.lineno + 1))
    return found


def tracked_files() -> list[str]:
    files = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout.split()
    picked = []
    for f in files:
        top = f.split("/", 1)[0]
        if "tests" in f.split("/")[:-1] or not (ROOT / f).is_file():
            continue
        if (top in CPP_ROOTS and f.endswith(CPP_SUFFIXES)) or (top in PY_ROOTS and f.endswith(".py")):
            picked.append(f)
    return sorted(picked)


def read_allow_list(path: Path) -> set[str]:
    if not path.exists():
        return set()
    entries = set()
    for raw in path.read_text().splitlines():
        entry = raw.split("#", 1)[0].strip()
        if entry:
            entries.add(entry)
    return entries


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--max-lines", type=int, default=MAX_LINES, help="longest function allowed")
    p.add_argument("--allow", type=Path, default=ROOT / "scripts" / "function_length_allow.txt", help="allow-list")
    args = p.parse_args()
    allowed = read_allow_list(args.allow)
    too_long, seen_allowed = [], set()
    files = tracked_files()
    for f in files:
        text = (ROOT / f).read_text(encoding="utf-8")
        functions = python_functions(text) if f.endswith(".py") else cpp_functions(text)
        for name, first, lines in functions:
            if lines <= args.max_lines:
                continue
            key = f"{f}:{name}"
            if key in allowed:
                seen_allowed.add(key)
            else:
                too_long.append(f"{f}:{first}: {name} is {lines} lines")
    for entry in sorted(allowed - seen_allowed):
        print(f"{args.allow.name}: {entry} is no longer over {args.max_lines} lines: remove it from the list")
    if too_long:
        print(f"functions over {args.max_lines} lines (split them into named helpers):")
        print("\n".join(too_long))
    ok = not too_long and allowed <= seen_allowed
    if ok:
        print(f"function length: {len(files)} files, none over {args.max_lines} lines ({len(allowed)} allowed)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
