#!/usr/bin/env python3
"""Function length: no function body in src/ longer than --max lines (default 120), counted from the
line of its opening brace to the line of its closing one (docs/STYLE: a long function is split into
named stages). Lambdas and blocks inside a function count as its lines; a lambda at namespace or
class scope counts as a function of its own.

    scripts/function-length.py [--max 120] [--list N] [PATH ...]   (default PATH: src)

Reads C++ as text: comments, string and character literals (raw strings too) are blanked first,
then braces are matched. A brace opens a function body where it follows a parenthesis at namespace
or class scope (a definition, a constructor with its initialisers); namespace, class, struct, union
and enum bodies and initialiser lists are scopes, not functions. Prints each function over the bound
(file:line: name, lines) and exits 1 if there is one; --list N prints the N longest.
"""

import argparse
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCOPE = re.compile(r"\b(namespace|class|struct|union|enum)\b|\bextern\s*$")


def blank(text):
    """text with comments and literals replaced by spaces (newlines kept, so lines still count)."""
    out, i, n = [], 0, len(text)
    keep = lambda s: re.sub(r"[^\n]", " ", s)
    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(keep(text[i:j]))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(keep(text[i:j]))
            i = j
        elif c == "R" and text.startswith('R"', i) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^()\\\s]{0,16})\(', text[i:])
            if not m:
                out.append(c)
                i += 1
                continue
            end = ")" + m.group(1) + '"'
            j = text.find(end, i + m.end())
            j = n if j < 0 else j + len(end)
            out.append('""' + keep(text[i + 2 : j - 1]) + " ")
            i = j
        elif c in "\"'":
            if c == "'" and i > 0 and text[i - 1].isalnum() and text[i - 2 : i].isalnum():
                out.append(c)  # a digit separator (1'000'000)
                i += 1
                continue
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            out.append(c + keep(text[i + 1 : j]) + (c if j < n else ""))
            i = j + 1
        else:
            out.append(c)
            i += 1
    return "".join(out)


def functions(path):
    """(name, first line, lines) of each function body in the file."""
    with open(path, encoding="utf-8", errors="replace") as f:
        text = blank(f.read())
    found = []
    stack = []  # (kind, line, name): kind "scope", "function", "member", "inner"
    head_start = 0
    line = 1
    for i, c in enumerate(text):
        if c == "\n":
            line += 1
        elif c in ";":
            head_start = i + 1
        elif c == "{":
            head = text[head_start:i]
            inside = stack[-1][0] if stack else "scope"
            name = ""
            if inside != "scope":
                kind = "inner"
            elif SCOPE.search(head) and "(" not in head.split("=")[0]:
                kind = "scope"
            elif re.search(r"\)[^()]*:[^:][^{]*[\w>]\s*$", head):
                kind = "member"  # a member's initialiser in a constructor's list: S() : v{1}
            elif ")" in head:
                kind = "function"
                m = re.findall(r"([~\w:]+|operator\s*\S+)\s*\(", head)
                name = m[0] if m else "(lambda)"
            else:
                kind = "inner"  # an initialiser list
            stack.append((kind, line, name))
            if kind != "member":
                head_start = i + 1
        elif c == "}":
            if stack:
                kind, first, name = stack.pop()
                if kind == "function":
                    found.append((name, first, line - first + 1))
                if kind == "member":
                    continue  # the constructor's head goes on
            head_start = i + 1
    return found


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--max", type=int, default=120)
    p.add_argument("--list", type=int, default=0, help="print the N longest functions")
    p.add_argument("paths", nargs="*", default=[os.path.join(ROOT, "src")])
    a = p.parse_args()
    every = []
    for top in a.paths:
        for base, _, files in os.walk(top):
            for f in sorted(files):
                if f.endswith((".cpp", ".h", ".hpp")):
                    path = os.path.join(base, f)
                    every += [(lines, os.path.relpath(path, ROOT), first, name) for name, first, lines in functions(path)]
    every.sort(reverse=True)
    for lines, path, first, name in every[: a.list]:
        print(f"{lines:5d}  {path}:{first}: {name}")
    long = [e for e in every if e[0] > a.max]
    for lines, path, first, name in long:
        print(f"function-length: {path}:{first}: {name} is {lines} lines (at most {a.max}: split it into named stages)",
              file=sys.stderr)
    print(f"function-length: {len(every)} functions, the longest {every[0][0] if every else 0} lines"
          f" ({every[0][1]}:{every[0][2]}: {every[0][3]})" if every else "function-length: no functions")
    return 1 if long else 0


if __name__ == "__main__":
    sys.exit(main())
