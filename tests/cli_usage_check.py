#!/usr/bin/env python3
"""`solidtex --help` names every flag each command accepts.

  cli_usage_check.py SOLIDTEX CLI_SOURCE_DIR

Reads the accepted flags from each cli/cmd_<command>.cpp's `Args args({...}, {...})` (the
parser's own lists, so a flag added there and not to the usage text fails here) and checks the
usage block of that command in `solidtex --help` mentions each of them.
"""
import re
import subprocess
import sys
from pathlib import Path


def usage_blocks(text: str) -> dict[str, str]:
    """The usage text split per command: a block starts at a line '  <command> ...'."""
    blocks: dict[str, str] = {}
    current = None
    for line in text.splitlines():
        m = re.match(r"^  ([a-z]+) ", line)
        if m:
            current = m.group(1)
            blocks[current] = ""
        if current:
            blocks[current] += line + "\n"
    return blocks


def accepted_flags(source: str) -> list[str]:
    m = re.search(r"Args args\(\{(.*?)\},\s*\{(.*?)\}\)", source, re.S)
    if not m:
        return []
    return re.findall(r'"(-[-a-z]+)"', m.group(1) + m.group(2))


def main() -> int:
    solidtex, cli_dir = sys.argv[1], Path(sys.argv[2])
    text = subprocess.run([solidtex, "--help"], capture_output=True, text=True, check=True).stdout
    blocks = usage_blocks(text)
    missing = []
    checked = 0
    for path in sorted(cli_dir.glob("cmd_*.cpp")):
        command = path.stem[len("cmd_"):]
        flags = accepted_flags(path.read_text())
        if not flags:
            continue
        if command not in blocks:
            missing.append(f"{command}: no usage block")
            continue
        for flag in flags:
            checked += 1
            if not re.search(re.escape(flag) + r"(?![-a-z])", blocks[command]):
                missing.append(f"{command} {flag}")
    if checked == 0:
        print("no Args lists found: the check would be empty", file=sys.stderr)
        return 1
    if missing:
        print("flags accepted but not in `solidtex --help`: " + ", ".join(missing), file=sys.stderr)
        return 1
    print(f"{checked} flags over {len(blocks)} commands documented")
    return 0


if __name__ == "__main__":
    sys.exit(main())
