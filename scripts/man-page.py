#!/usr/bin/env python3
"""Writes fourierflare(1), the man page, from the CLI's own help: `fourierflare --help` and each
command's `--help` (lens's subcommands included), so the page says what the binary does.

    scripts/man-page.py BUILD/src/cli/fourierflare OUT/fourierflare.1

The page's date is SOURCE_DATE_EPOCH's when set (reproducible packages), else left out."""

import os
import re
import subprocess
import sys
import time


def help_of(binary, *command):
    p = subprocess.run([binary, *command, "--help"], capture_output=True, text=True, timeout=60)
    if p.returncode != 0:
        sys.exit(f"man-page: '{binary} {' '.join(command)} --help' exited {p.returncode}: {p.stderr}")
    return p.stdout


def subcommands(text):
    """The names listed under 'Subcommands:' in a CLI11 help text."""
    names, inside = [], False
    for line in text.splitlines():
        if line.strip() == "Subcommands:":
            inside = True
        elif inside and re.match(r"^  \S", line):
            names.append(line.split()[0])
        elif inside and line.strip() == "":
            inside = False
    return names


def roff(text):
    """Plain text as roff: backslashes escaped, no line read as a request, hyphens as minus signs."""
    out = []
    for line in text.rstrip("\n").splitlines():
        line = line.replace("\\", "\\e").replace("-", "\\-")
        if line.startswith((".", "'")):
            line = "\\&" + line
        out.append(line)
    return "\n".join(out)


def block(text):
    return ".nf\n" + roff(text) + "\n.fi\n"


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    binary, output = sys.argv[1], sys.argv[2]
    version = subprocess.run([binary, "--version"], capture_output=True, text=True, timeout=60).stdout.strip()
    top = help_of(binary)
    epoch = os.environ.get("SOURCE_DATE_EPOCH")
    date = time.strftime("%Y-%m-%d", time.gmtime(int(epoch))) if epoch else ""
    page = [
        f'.TH FOURIERFLARE 1 "{date}" "{version}" "User Commands"',
        ".SH NAME",
        "fourierflare \\- physically based lens flares from real lens prescriptions",
        ".SH SYNOPSIS",
        ".B fourierflare",
        "[\\fIOPTIONS\\fR] \\fICOMMAND\\fR [\\fICOMMAND OPTIONS\\fR]",
        ".SH DESCRIPTION",
        "FourierFlare reads lens prescriptions (.lens, Zemax .zmx, pbrt .dat), traces the direct image and "
        "every two-bounce ghost, adds the iris's diffraction and composites the flare onto HDR plates. "
        "The text below is the program's own help, command by command.",
        ".SH OPTIONS",
        block(top),
        ".SH COMMANDS",
    ]
    for name in subcommands(top):
        text = help_of(binary, name)
        page += [f'.SS "fourierflare {name}"', block(text)]
        for sub in subcommands(text):
            page += [f'.SS "fourierflare {name} {sub}"', block(help_of(binary, name, sub))]
    page += [
        ".SH ENVIRONMENT",
        ".TP\n.B FOURIERFLARE_LENS_PATH\nColon-separated folders searched for a lens given by name "
        "(before the installed lenses).",
        ".TP\n.B FOURIERFLARE_DATA_DIR\nThe bundled data folder, instead of the installed one.",
        ".TP\n.B FF_CACHE_DIR\nThe ghost-table and PSF cache (default: $XDG_CACHE_HOME/fourierflare or "
        "~/.cache/fourierflare).",
        ".TP\n.B FF_PLATE_CHECK_SECONDS\nThe CPU time (seconds, default 3) the check of a plate's header may "
        "spend before the file is refused as hanging the image library; its pixels get as much again plus 1 s "
        "per 25 MB, and each stage 20 times its CPU bound of wall-clock time.",
        ".TP\n.B SOURCE_DATE_EPOCH\nThe time stamp written into image headers (seconds since 1970, UTC); "
        "without it none is written, so the same command writes the same bytes.",
        ".SH FILES",
        ".TP\n.I <prefix>/share/fourierflare/lenses\nThe bundled lenses, found by name "
        "(\\fB\\-\\-lens double\\-gauss\\-50mm\\-f2\\fR).",
        ".TP\n.I <prefix>/share/fourierflare/night-street.exr\nThe sample plate.",
        ".TP\n.I <prefix>/share/fourierflare/glass\nThe glass catalogues (also built into the program).",
        ".SH EXIT STATUS",
        "0 success, 1 runtime failure, 2 usage or input error.",
    ]
    text = "\n".join(page) + "\n"
    tmp = output + ".tmp"
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, output)


if __name__ == "__main__":
    main()
