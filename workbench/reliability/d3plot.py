"""Damaged copies of a d3plot family (:func:`run_d3plot_stress`): a member cut at a random byte,
random bytes overwritten, a block zeroed, a member other than the first removed, one byte of
the header changed. Each copy must be refused with ParseError or read with every field that
survives: nothing else raised, no hang, and each read compared with the read of the undamaged
family (:func:`compare_read`).

A member is removed only where the files show its loss: a member followed by another, or
the one that holds every state; a lost last member that leaves states looks like the end of
the run, and no reader can tell.

* Node coordinates, connectivity, part ids and titles, node and element ids equal, unless the
  damage lies in the geometry section (a changed value there cannot be told) or a warning
  names them ("part ids", "node ids", "element ids", "part titles").
* Every state of the undamaged read that is absent is named in a ParseWarning (one that speaks
  of states): else "silent loss". So is every field absent from a read with states (a warning
  that names the field), and state coordinates.
* Every state read is a state of the undamaged read, found by its time (by its order where a
  warning says the times could not be read), with equal coordinates and fields, unless the
  damage lies in that state's bytes; a warning naming the field (or "coordinates") excuses a
  difference, one naming the damaged member as damaged a state read from stray bytes. Else
  "wrong data", with what differs.

The undamaged copy itself is read first: it must equal the undamaged read with no warning.
Damage ``i`` of seed ``s`` is drawn from ``random.Random(f"d3plot family:{s}:{i}")`` (and
:func:`damaged_d3plot` for the byte damages), so every failure is reproduced by its seed and
index alone.
"""

from __future__ import annotations

import random
import re
import tempfile
import time
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .readers import TIMEOUT_S, read_outcome

D3PLOT_KINDS = ("truncate", "garble", "zero block")
FAMILY_KINDS = (*D3PLOT_KINDS, "missing member", "header byte")
D3PLOT_OUTCOMES = ("read", "parse error", "silent loss", "wrong data", "other exception", "hang")
D3PLOT_FAILING = ("silent loss", "wrong data", "other exception", "hang")
HEADER_WORDS = 64  # the control words at the start of the first file


@dataclass
class D3plotStressReport:
    """Outcomes of ``n`` damaged copies of a d3plot family: ``counts`` (kind → outcome → count;
    the outcomes are "read" — whole, or with what is missing named in warnings —, "parse
    error", "silent loss", "wrong data", "other exception" and "hang"), ``failures`` (one line
    each, with the seed and index that reproduce it) and ``seconds``."""

    n: int
    seed: int
    counts: dict
    failures: list
    seconds: float

    @property
    def ok(self) -> bool:
        return not self.failures

    def table(self) -> str:
        rows = [f"{'d3plot damage':<15}" + "".join(f"{o:>16}" for o in D3PLOT_OUTCOMES)]
        rows.append("-" * len(rows[0]))
        for kind in FAMILY_KINDS:
            rows.append(f"{kind:<15}"
                        + "".join(f"{self.counts[kind][o]:>16}" for o in D3PLOT_OUTCOMES))
        return "\n".join(rows)


def damaged_d3plot(data: bytes, index: int, seed: int) -> tuple[str, bytes]:
    """(kind, bytes) of damage ``index`` of ``seed`` to the d3plot ``data``: cut at a random
    byte, 1–16 random bytes overwritten, or a block of up to 4 KiB zeroed."""
    rng = random.Random(f"d3plot:{seed}:{index}")
    kind = rng.choice(D3PLOT_KINDS)
    damaged = bytearray(data)
    if kind == "truncate":
        del damaged[rng.randrange(64, len(damaged)):]
    elif kind == "garble":
        for _ in range(rng.randint(1, 16)):
            damaged[rng.randrange(len(damaged))] = rng.randrange(256)
    else:
        start = rng.randrange(len(damaged))
        end = min(len(damaged), start + rng.randint(1, 4096))
        damaged[start:end] = bytes(end - start)
    return kind, bytes(damaged)


@dataclass
class Damage:
    """What :func:`damaged_family` did: ``kind`` to the member ``member`` (a file name), in its
    bytes ``start`` to ``stop``; ``lost`` when those bytes are gone (cut, or the member
    removed); ``data`` the member's new bytes, None when it is removed."""

    kind: str
    member: str
    start: int
    stop: int
    lost: bool
    data: bytes | None

    def __str__(self) -> str:
        return f"{self.kind} of {self.member}, bytes {self.start}..{self.stop}"


def damaged_family(members: dict[str, bytes], index: int, seed: int, word: int = 4,
                   removable: list[str] | None = None) -> Damage:
    """Damage ``index`` of ``seed`` to the d3plot family ``members`` (file name → bytes, the
    first file first; ``word`` bytes a word): one byte of the first file's header changed
    (1 in 5), one of the ``removable`` members (default: every member after the first)
    removed (1 in 6, where there is one), else :func:`damaged_d3plot` to a member drawn at
    random."""
    rng = random.Random(f"d3plot family:{seed}:{index}")
    names = list(members)
    removable = names[1:] if removable is None else removable
    roll = rng.random()
    if roll < 0.2:
        data = bytearray(members[names[0]])
        at = rng.randrange(min(len(data), HEADER_WORDS * word))
        data[at] ^= rng.randrange(1, 256)
        return Damage("header byte", names[0], at, at + 1, False, bytes(data))
    if roll < 0.2 + 1 / 6 and removable:
        name = rng.choice(removable)
        return Damage("missing member", name, 0, len(members[name]), True, None)
    name = rng.choice(names)
    original = members[name]
    kind, data = damaged_d3plot(original, index, seed)
    if kind == "truncate":
        return Damage(kind, name, len(data), len(original), True, data)
    changed = np.flatnonzero(np.frombuffer(original, np.uint8) != np.frombuffer(data, np.uint8))
    start, stop = (int(changed[0]), int(changed[-1]) + 1) if len(changed) else (0, 0)
    return Damage(kind, name, start, stop, False, data)


def run_d3plot_stress(n: int, seed: int, source=None, timeout: float = TIMEOUT_S,
                      reader=None) -> D3plotStressReport | None:
    """Read ``n`` damaged copies of the d3plot family of ``source`` (default: the shared
    d3plot; None when it is absent) with ``reader`` (``path -> FEMesh``; default
    :func:`~workbench.scene.readers.d3plot.read_d3plot`) and compare each read with the
    undamaged family read by ``read_d3plot`` (module notes); never past ``timeout`` seconds a
    read."""
    from ..data import D3PLOT, shared_file
    from ..scene.readers.d3plot import family_layout, read_d3plot
    from ..scene.readers.d3plot_family import family_members

    source = shared_file(D3PLOT) if source is None else Path(source)
    if source is None:
        return None
    reader = reader or read_d3plot
    layout = family_layout(source)
    files = {path.name: path.read_bytes() for path in family_members(Path(source))}
    removable = _detectable_losses(layout)
    reference = read_d3plot(layout[0].path)
    counts = {kind: dict.fromkeys(D3PLOT_OUTCOMES, 0) for kind in FAMILY_KINDS}
    failures = []
    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="workbench-stress-") as folder:
        folder = Path(folder)
        for name, data in files.items():
            (folder / name).write_bytes(data)
        first = folder / layout[0].path.name
        outcome, why = _judged(first, timeout, reader, reference, layout, None)
        if outcome != "read":
            failures.append(f"d3plot seed {seed} undamaged copy: {outcome}: {why}")
        for index in range(n):
            damage = damaged_family(files, index, seed, removable=removable)
            target = folder / damage.member
            if damage.data is None:
                target.unlink()
            else:
                target.write_bytes(damage.data)
            try:
                outcome, why = _judged(first, timeout, reader, reference, layout, damage)
            finally:
                target.write_bytes(files[damage.member])
            counts[damage.kind][outcome] += 1
            if outcome in D3PLOT_FAILING:
                failures.append(f"d3plot seed {seed} index {index} ({damage}): {outcome}: {why}")
    return D3plotStressReport(n, seed, counts, failures, time.perf_counter() - start)


def _detectable_losses(layout) -> list[str]:
    """The members after the first whose loss the files show: one followed by another member,
    or one without which no state is left (a lost last member otherwise looks like the end
    of the run)."""
    total = sum(min(m.states, m.read) for m in layout)
    return [m.path.name for k, m in enumerate(layout[1:], 1)
            if k < len(layout) - 1 or total == min(m.states, m.read)]


def _judged(path: Path, timeout: float, reader, reference, layout, damage) -> tuple[str, str]:
    """(outcome, why) of one read of the family at ``path`` by ``reader``."""
    from ..scene.readers import ParseWarning

    def recording(target):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            mesh = reader(target)
        return mesh, [str(w.message) for w in caught if issubclass(w.category, ParseWarning)]

    result, outcome, why = read_outcome(path, timeout, recording)
    if outcome != "read":
        return outcome, why
    mesh, said = result
    if damage is None and said:
        return "wrong data", f"warnings on the undamaged family: {said[0]}"
    return compare_read(mesh, said, reference, layout, damage)


def _touched(layout, damage) -> tuple[set[int], bool, bool]:
    """(the states of the undamaged family whose bytes the damage lies in, whether it lies in
    the geometry section, whether in the header)."""
    if damage is None:
        return set(), False, False
    states, offset = set(), 0
    for k, member in enumerate(layout):
        count = min(member.states, member.read)
        if member.path.name == damage.member:
            for i in range(count):
                a = member.start + i * member.state_bytes
                if damage.start < a + member.state_bytes and a < damage.stop:
                    states.add(offset + i)
            if k == 0:
                header = HEADER_WORDS * 4
                return states, damage.start < member.start and damage.stop > header, \
                    damage.start < header
        offset += count
    return states, False, False


def compare_read(mesh, said: list[str], reference, layout, damage) -> tuple[str, str]:
    """("read", "") when ``mesh`` (read with the warnings ``said``) keeps every value of the
    undamaged ``reference`` that the ``damage`` (a :class:`Damage`, None for the undamaged
    copy; ``layout`` the undamaged family's members) did not lie in, and names in a warning
    every state and field it lacks; else ("silent loss" or "wrong data", what differs)."""
    touched, geometry, _ = _touched(layout, damage)
    text = " ".join(said).lower()

    def named(word: str) -> bool:  # a whole word: "_read_states_shell" names no state
        return re.search(rf"\b{re.escape(word)}\b", text) is not None

    for name, excuse in (("nodes", None), ("elements", None), ("parts", "part ids"),
                         ("node_ids", "node ids"), ("element_ids", "element ids"),
                         ("part_names", "part titles")):
        a, b = getattr(mesh, name), getattr(reference, name)
        if not geometry and not (excuse and named(excuse)) and not _equal(a, b):
            return "wrong data", f"{name} differ from the undamaged read"
    same_shape = mesh.nodes.shape == reference.nodes.shape and \
        mesh.elements.shape == reference.elements.shape
    ref_times = [] if reference.times is None else reference.times.tolist()
    times = [] if mesh.times is None else mesh.times.tolist()
    by_index = named("times")  # the times could not be read: match states by their order
    matched, j = [], 0
    for i, t in enumerate(times):
        if by_index:
            k = i if i < len(ref_times) else None
        else:
            k = next((k for k in range(j, len(ref_times)) if ref_times[k] == t), None)
            if k is None:
                k = next((k for k in sorted(touched) if k >= j), None)
        if k is None and damage is not None and not damage.lost and \
                named(damage.member.lower()) and named("damaged"):
            continue  # the member's end is damaged, as a warning says: stray bytes read
        if k is None:
            return "wrong data", f"state {i} (t = {t:g}) is no state of the undamaged read"
        matched.append((i, k))
        j = k + 1
    lost = sorted(set(range(len(ref_times))) - {k for _, k in matched})
    if lost and not (named("state") or named("states")):
        return "silent loss", (f"{len(lost)} of {len(ref_times)} states not read (t = "
                               f"{', '.join(f'{ref_times[k]:g}' for k in lost[:3])}) and no "
                               f"warning names them")
    if times:
        for name in reference.element_fields:
            if name not in mesh.element_fields and not named(name):
                return "silent loss", f"field {name!r} not read and no warning names it"
    for name in mesh.element_fields:
        if name not in reference.element_fields:
            return "wrong data", f"field {name!r} is not in the undamaged read"
    if times and mesh.steps is None and reference.steps is not None and not named("coordinates"):
        return "silent loss", "the node coordinates of the states not read"
    for name, values in mesh.element_fields.items():
        if times and values.ndim != 2:
            return "wrong data", f"field {name!r} is not per state ({values.shape})"
    if not same_shape:
        return "read", ""
    for i, k in matched:
        if k in touched:
            continue
        if mesh.steps is not None and not named("coordinates") and \
                not _equal(mesh.steps[i], reference.steps[k]):
            return "wrong data", f"the node coordinates of state {k} differ"
        for name, values in mesh.element_fields.items():
            ref = reference.element_fields[name][k]
            if not named(name) and not _equal(values[i], ref):
                bad = np.flatnonzero(~((values[i] == ref) | (np.isnan(values[i])
                                                             & np.isnan(ref))))
                e = int(bad[0])
                return "wrong data", (f"field {name!r} of state {k} (t = {ref_times[k]:g}) "
                                      f"differs at {len(bad)} element(s), first element index "
                                      f"{e}: {values[i][e]:g}, undamaged {ref[e]:g}")
    return "read", ""


def _equal(a, b) -> bool:
    """Whether two arrays (or None, or dicts) are equal, NaN equal to NaN."""
    if a is None or b is None or isinstance(a, dict):
        return a == b if isinstance(a, dict) else a is None and b is None
    a, b = np.asarray(a), np.asarray(b)
    if a.shape != b.shape:
        return False
    if a.dtype.kind == "f" or b.dtype.kind == "f":
        return bool(np.array_equal(a, b, equal_nan=True))
    return bool(np.array_equal(a, b))
