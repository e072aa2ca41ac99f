#!/usr/bin/env python3
"""scripts/function-length.py against files written here, whose functions' lengths are known: it
must flag the long one (and only it) wherever it hides, and pass the short ones."""

import os
import subprocess
import sys
import tempfile

SCRIPT = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))), "scripts",
                      "function-length.py")


def check(source, bound):
    with tempfile.TemporaryDirectory() as d:
        with open(os.path.join(d, "x.cpp"), "w") as f:
            f.write(source)
        r = subprocess.run([sys.executable, SCRIPT, "--max", str(bound), "--list", "10", d], capture_output=True,
                           text=True)
    return r.returncode, r.stdout, r.stderr


def body(lines):
    """A function body of exactly `lines` lines, brace to brace, with braces in literals and comments."""
    inner = ['    const char* s = "}}}";  // }', "    /* { */ int x = '}';", '    auto r = R"(}})";']
    inner += ["    x += 1;"] * (lines - 2 - len(inner))
    return "{\n" + "\n".join(inner) + "\n}\n"


SOURCE = ("namespace a {\nstruct S {\n    int v{0};\n    void member() " + body(130) + "};\n"
          "int shortOne(int y) " + body(120) + "const int table[] = {1, 2, 3};\n"
          "S::S(int k) : v{k}, w(2) " + body(125) + "} // namespace a\n")

code, out, err = check(SOURCE, 120)
assert code == 1, (code, out, err)
assert "x.cpp:4: member is 130 lines" in err, err
assert "shortOne" not in err, err
assert "x.cpp:256: S::S is 125 lines" in err, err
assert " 120  " in out and "shortOne" in out, out
code, out, err = check(SOURCE, 130)
assert code == 0, (code, out, err)
print("function-length.py: flags a 130-line member and a 125-line constructor, passes 120 lines, ignores braces in literals")
