"""``MOAS_GUI_CONTROL_HOOK`` for a ``moas-server --edit`` process in
``test_builder_restart_remote.py``: the builder's hands, one round for each line the
test writes on standard input (``SHORT ANSWERS``, the answers as ``yes,no``).  Each round
sets antenna 0's short name to SHORT, triggers File > Save and Restart (the diff is
answered with Save, each question in turn from ANSWERS), prints each question
(``QUESTION "..."``) and the server's final answer (``ANSWER "..."``) on standard output.
An empty line (or the end of the input) closes the window."""

from __future__ import annotations

import asyncio
import json
import sys
from collections.abc import Callable
from typing import Any


class Hands:
    def __init__(self, window: Any) -> None:
        self.window = window
        self.answers: list[bool] = []
        self.task: asyncio.Task[None] | None = None

    def ask(self, title: str, text: str, answered: Callable[[bool], None]) -> None:
        print("QUESTION", json.dumps(f"{title}: {text}"), flush=True)
        answered(self.answers.pop(0))

    async def rounds(self) -> None:
        while words := (await asyncio.to_thread(sys.stdin.readline)).split():
            short, answers = words[0], words[1] if len(words) > 1 else ""
            self.answers = [word == "yes" for word in answers.split(",") if word]
            self.window.server_answer = None
            self.window.doc.set(("Antennas", 0, "ShortName"), short)
            self.window.action_apply.trigger()
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
    hands.task = asyncio.get_running_loop().create_task(hands.rounds())
    return hands
