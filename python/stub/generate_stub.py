#!/usr/bin/env python3
"""Writes the stub of the package vertexflow: the template (vertexflow.pyi.in) with each line
"# <enhance options ...>" replaced by every option of the library's table, as the built module
gives it. The build runs it after the module (python/CMakeLists.txt); a test runs it again and
fails if the stub it finds differs (python/tests/test_options.py).

    PYTHONPATH=build/python python3 python/stub/generate_stub.py python/stub/vertexflow.pyi.in OUT

OUT '-' writes to standard output.
"""

import os
import sys

from vertexflow import _options

# Each placeholder, and how it types the option that changes the faces (None: as the others).
PLACEHOLDERS = {
    "# <enhance options>": None,
    "# <enhance options, faces unchanged>": False,
    "# <enhance options, faces changed>": True,
}


def stub_text(template: str) -> str:
    lines = []
    for line in template.splitlines():
        key = line.strip()
        if key in PLACEHOLDERS:
            indent = line[: len(line) - len(line.lstrip())]
            lines.extend(_options.stub_option_lines(PLACEHOLDERS[key], indent))
        else:
            lines.append(line)
    return "\n".join(lines) + "\n"


def main(argv: list[str]) -> int:
    if len(argv) != 3:
        sys.exit(__doc__)
    with open(argv[1]) as f:
        text = stub_text(f.read())
    if argv[2] == "-":
        sys.stdout.write(text)
        return 0
    tmp = argv[2] + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, argv[2])
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
