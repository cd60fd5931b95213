"""``MOAS_GUI_CONTROL_HOOK`` for a ``moas-server --edit`` process in
``test_builder_restart_remote.py``: the builder's hands.  It sets antenna 0's short name
to ``BUILDER_HOOK_SHORT``, answers the diff with Save and each question in turn from
``BUILDER_HOOK_ANSWERS`` (``yes,no``), triggers File > Save and Restart, prints each
question (``QUESTION "..."``) and the server's final answer (``ANSWER "..."``) on standard
output, and closes the window."""

from __future__ import annotations

import asyncio
import json
import os
from collections.abc import Callable
from typing import Any


class Hands:
    def __init__(self, window: Any) -> None:
        self.window = window
        self.answers = [word == "yes" for word in
                        os.environ.get("BUILDER_HOOK_ANSWERS", "").split(",") if word]
        self.task: asyncio.Task[None] | None = None

    def ask(self, title: str, text: str, answered: Callable[[bool], None]) -> None:
        print("QUESTION", json.dumps(f"{title}: {text}"), flush=True)
        answered(self.answers.pop(0))

    async def report(self) -> None:
        while self.window.server_answer is None:
            await asyncio.sleep(0.05)
        print("ANSWER", json.dumps(self.window.server_answer.said), flush=True)
        self.window.closing_confirmed = True
        self.window.close()

    async def close(self) -> None:
        if self.task is not None:
            await self.task


async def start(window: Any) -> Hands:
    hands = Hands(window)
    window.ask = hands.ask
    window.show_diff = lambda _diff, answered: answered(True)
    window.doc.set(("Antennas", 0, "ShortName"), os.environ["BUILDER_HOOK_SHORT"])
    window.action_apply.trigger()
    hands.task = asyncio.get_running_loop().create_task(hands.report())
    return hands
