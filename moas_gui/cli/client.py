"""``moas-client``: the button and compass client window for another computer."""

from __future__ import annotations

import sys


def main(argv: list[str] | None = None) -> int:
    print("moas-client: the client window is not built yet.", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
