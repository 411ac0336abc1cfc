"""`python3 -m bdptref ARGS...` runs the bdptref command line (docs/library.md).

The binary is the one installed with this package (PREFIX/bin/bdptref, found relative to the
package), else $BDPTREF_BINARY, else `bdptref` on PATH. Its exit code is returned unchanged.
"""
import os
import sys

from bdptref import cli_binary


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    binary = cli_binary()
    if binary is None:
        sys.stderr.write("bdptref: the bdptref binary was not found next to the Python package, in "
                         "$BDPTREF_BINARY or on PATH\n")
        return 2
    os.execv(binary, [binary] + list(argv))  # replaces this process: signals and exit code are the CLI's


if __name__ == "__main__":
    sys.exit(main())
