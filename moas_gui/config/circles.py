"""Finding systems that contain each other in a circle, in time linear in the file."""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence

MAX_CIRCLES = 5
"""Circles reported at most: past a few, more sentences do not help anyone fix a file."""


def circles(order: Sequence[int], children: Mapping[int, Sequence[int]],
            limit: int = MAX_CIRCLES) -> list[list[int]]:
    """Circles of two or more systems, each as a path that ends where it starts.

    ``order`` is the file order; each circle starts at its member that comes first
    in it, and no system appears in two reported circles.  A system that contains
    itself directly is not a circle here (it has its own sentence).
    """
    rank = {ident: index for index, ident in enumerate(order)}
    state: dict[int, int] = {}  # 1: on the current path, 2: finished
    found: list[list[int]] = []
    reported: set[int] = set()
    for root in order:
        if root in state:
            continue
        path: list[int] = [root]
        at: dict[int, int] = {root: 0}
        state[root] = 1
        walks: list[Iterator[int]] = [iter(children.get(root, ()))]
        while walks:
            child = next(walks[-1], None)
            if child is None:
                walks.pop()
                node = path.pop()
                del at[node]
                state[node] = 2
                continue
            seen = state.get(child)
            if seen is None:
                state[child] = 1
                at[child] = len(path)
                path.append(child)
                walks.append(iter(children.get(child, ())))
            elif seen == 1 and child != path[-1] and child not in reported:
                circle = path[at[child]:]
                if reported.isdisjoint(circle):
                    reported.update(circle)
                    start = min(range(len(circle)), key=lambda i: rank.get(circle[i], len(rank)))
                    found.append(circle[start:] + circle[:start] + [circle[start]])
                    if len(found) >= limit:
                        return found
    return found


def chain(circle: Sequence[int], shown: int = 8) -> str:
    """``system 1 -> system 2 -> system 1``; a long circle shows its start and its length."""
    if len(circle) <= shown + 1:
        return " -> ".join(f"system {i}" for i in circle)
    head = " -> ".join(f"system {i}" for i in circle[:shown])
    return f"{head} -> ... -> system {circle[-1]} ({len(circle) - 1:,} systems)"


__all__ = ["MAX_CIRCLES", "chain", "circles"]
