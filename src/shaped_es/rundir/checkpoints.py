"""A run's checkpoints: ``RUN/checkpoints/gen_NNNNNN.npz`` (arrays, never pickle) and ``.json`` (metadata),
saved atomically (``.npz``, then ``.json``, then ``latest.json``), found by scanning (``latest.json`` is
advisory) and loaded only if they are this run's own: the arrays name the run and generation
(:func:`bind`), the ``.json`` holds their sha256 (:func:`arrays_digest`).

:class:`CheckpointFiles` is :class:`~shaped_es.rundir.store.RunStore`'s part that does this (it uses the
store's ``ckpt_dir``, ``run_id()`` and ``_check_writable()``).
"""

from __future__ import annotations

import hashlib
import io
import json
import re
import zipfile
from pathlib import Path

import numpy as np

from shaped_es.rundir.atomic import StoreError, atomic_write_bytes, atomic_write_text, read_regular

BIND_PREFIX = "checkpoint/"  # a checkpoint's arrays name their run and generation (bind())
RUN_KEY, GEN_KEY = BIND_PREFIX + "run_id", BIND_PREFIX + "generation"
DIGEST_KEY = "arrays_sha256"  # ... and its .json holds their digest (arrays_digest())
_CKPT_RE = re.compile(r"gen_(\d{6,})")


class CheckpointFiles:
    """The checkpoint methods of :class:`~shaped_es.rundir.store.RunStore`."""

    def _check_ckpt_dir(self) -> bool:
        """True if the checkpoint directory exists; ``StoreError`` if something else is in its place."""
        if not self.ckpt_dir.exists():
            return False
        if not self.ckpt_dir.is_dir():
            raise StoreError(f"{self.ckpt_dir} is not a directory; move it away to resume")
        return True

    def save_checkpoint(self, generation: int, arrays: dict[str, np.ndarray], meta: dict, keep: int) -> Path:
        self._check_writable()
        if self.ckpt_dir.exists() and not self.ckpt_dir.is_dir():
            raise StoreError(f"{self.ckpt_dir} is not a directory; move it away to resume")
        name = f"gen_{generation:06d}"
        arrays = {k: np.asarray(v) for k, v in arrays.items()} | bind(self.run_id(), generation)
        buf = io.BytesIO()
        np.savez(buf, **arrays)
        atomic_write_bytes(self.ckpt_dir / f"{name}.npz", buf.getvalue())
        atomic_write_text(self.ckpt_dir / f"{name}.json", json.dumps({**meta, "generation": generation,
                                                                      DIGEST_KEY: arrays_digest(arrays)}))
        atomic_write_text(self.ckpt_dir / "latest.json", json.dumps({"name": name}))
        # only the run's own names (gen_NNNNNN.npz / .json): a user's gen_000028_backup.npz beside them is not ours
        ours = sorted((int(m.group(1)), p) for p in self.ckpt_dir.glob("gen_*.npz")
                      if (m := _CKPT_RE.fullmatch(p.name[:-4])) is not None)
        for _, old in ours[:-keep]:
            old.unlink(missing_ok=True)
            old.with_suffix(".json").unlink(missing_ok=True)
        return self.ckpt_dir / f"{name}.npz"

    def checkpoints(self) -> list[int]:
        """Generations of the complete checkpoints on disk (``.npz`` and ``.json`` both present), ascending."""
        if not self._check_ckpt_dir():
            return []
        names = {p.name for p in self.ckpt_dir.iterdir()}
        gens = []
        for n in names:
            m = _CKPT_RE.fullmatch(n[:-4]) if n.endswith(".npz") else None
            if m and f"{n[:-4]}.json" in names:
                gens.append(int(m.group(1)))
        return sorted(gens)

    def _latest_named(self) -> int | None:
        """The generation ``latest.json`` names (None if absent or unreadable); ``StoreError`` if it names
        anything but a checkpoint of this directory (``../../x``)."""
        latest = self.ckpt_dir / "latest.json"
        try:
            data = json.loads(read_regular(latest).decode("utf-8"))
        except (OSError, ValueError):  # absent, binary or not JSON: it is advisory, the scan decides
            return None
        name = data.get("name") if isinstance(data, dict) else None
        if name is None:
            return None
        m = _CKPT_RE.fullmatch(name) if isinstance(name, str) else None
        if m is None:
            raise StoreError(f"{latest} names {name!r}, which is not a checkpoint of this run (gen_NNNNNN); "
                             f"delete {latest.name} to resume from the newest checkpoint found")
        return int(m.group(1))

    def newest_generation(self) -> int:
        """Generations covered by the newest complete checkpoint (0 without one); reads no arrays."""
        gens = self.checkpoints()
        return gens[-1] if gens else 0

    def checkpoint_meta(self) -> dict | None:
        """The newest complete checkpoint's metadata, None without one."""
        loaded = self.load_checkpoint()
        return None if loaded is None else loaded[1]

    def require_checkpoint(self) -> tuple[dict[str, np.ndarray], dict]:
        """:meth:`load_checkpoint`, with one clear ``StoreError`` when the run has none yet."""
        loaded = self.load_checkpoint()
        if loaded is None:
            raise StoreError(f"{self.root} has no checkpoint yet")
        return loaded

    def load_checkpoint(self) -> tuple[dict[str, np.ndarray], dict] | None:
        """The newest complete checkpoint as (arrays, meta), or None if the run has none yet.

        Found by scanning ``checkpoints/`` (``latest.json`` is advisory: it may lag a kill by one
        checkpoint, or be missing); one that is unreadable is an error naming it, never silently
        skipped."""
        gens = self.checkpoints()
        named = self._latest_named() if self.ckpt_dir.is_dir() else None
        if named is not None and (not gens or named > gens[-1]):
            have = f"the newest found is gen_{gens[-1]:06d}" if gens else "none is found"
            raise StoreError(f"{self.ckpt_dir}/latest.json names gen_{named:06d}, which is missing "
                             f"({have}); delete latest.json to resume from what is there")
        if not gens:
            return None
        g = gens[-1]
        name = f"gen_{g:06d}"
        older = self.fallback_hint(g)
        try:
            meta = json.loads(read_regular(self.ckpt_dir / f"{name}.json").decode("utf-8"))
            with np.load(io.BytesIO(read_regular(self.ckpt_dir / f"{name}.npz")), allow_pickle=False) as z:
                arrays = {k: z[k] for k in z.files}
        except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile) as exc:
            why = type(exc).__name__
            raise StoreError(f"checkpoint {name} in {self.ckpt_dir} is unreadable ({why}){older}") from None
        if not isinstance(meta, dict) or type(meta.get("generation")) is not int or meta["generation"] != g:
            raise StoreError(f"checkpoint {name} in {self.ckpt_dir} is unreadable (its .json is not this "
                             f"checkpoint's metadata){older}")
        why = self._foreign(arrays, meta, g)
        if why:
            raise StoreError(f"checkpoint {name} in {self.ckpt_dir} {why}{older}")
        return {k: v for k, v in arrays.items() if not k.startswith(BIND_PREFIX)}, meta

    def fallback_hint(self, g: int) -> str:
        """``; if only this checkpoint is damaged, move gen_G.npz and gen_G.json [and latest.json] out of
        DIR to resume from gen_F`` (the newest checkpoint before ``g``), or "" without one: what to do when
        checkpoint ``g`` cannot be taken (``latest.json`` too where it names ``g``: it would then name a
        missing checkpoint). Moved, not deleted: where every checkpoint fails alike, the run's setup changed
        (its config, ``label_probe.json``), not the checkpoint, and moving them back loses nothing."""
        older = [x for x in self.checkpoints() if x < g]
        name = f"gen_{g:06d}"
        named = self._latest_named() if self.ckpt_dir.is_dir() else None
        files = f"{name}.npz, {name}.json and latest.json" if named is not None and named >= g \
            else f"{name}.npz and {name}.json"
        return (f"; if only this checkpoint is damaged, move {files} out of {self.ckpt_dir} to resume from "
                f"gen_{older[-1]:06d}") if older else ""

    def _foreign(self, arrays: dict[str, np.ndarray], meta: dict, g: int) -> str | None:
        """Why generation ``g``'s checkpoint (``arrays`` and ``meta`` as loaded) is not this run's own,
        or None: its arrays must name this run and generation ``g`` (:func:`bind`) and hash to the digest
        its ``.json`` holds. A checkpoint made before checkpoints were bound has neither (taken as is)."""
        bound = {k for k in arrays if k.startswith(BIND_PREFIX)}
        if not bound and DIGEST_KEY not in meta:
            return None
        if bound != {RUN_KEY, GEN_KEY} or not isinstance(meta.get(DIGEST_KEY), str):
            return "has arrays and metadata that were not saved together (one of its files replaced?)"
        rid, gen = arrays[RUN_KEY], arrays[GEN_KEY]
        if rid.dtype.kind != "U" or rid.shape != () or gen.dtype.kind != "i" or gen.shape != ():
            return "has malformed binding arrays (checkpoint/run_id, checkpoint/generation)"
        if str(rid) != (self.run_id() or ""):
            return f"holds the arrays of another run (run {str(rid) or 'without an id'}, not {self.run_id()})"
        if int(gen) != g:
            return f"holds generation {int(gen)}'s arrays, not generation {g}'s (an older checkpoint renamed?)"
        if arrays_digest(arrays) != meta[DIGEST_KEY]:
            return "holds arrays that are not the ones its .json was saved with (sha256 differs: edited or replaced?)"
        return None


def bind(run_id: str | None, generation: int) -> dict[str, np.ndarray]:
    """The arrays that bind a checkpoint's ``.npz`` to its run and generation (no pickle: a str and an
    int64 scalar)."""
    return {RUN_KEY: np.array(run_id or ""), GEN_KEY: np.array(generation, dtype=np.int64)}


def arrays_digest(arrays: dict[str, np.ndarray]) -> str:
    """sha256 of every array (name, dtype, shape, bytes, in name order): the ``.json``'s proof that the
    ``.npz`` beside it is the one saved with it."""
    h = hashlib.sha256()
    for k in sorted(arrays):
        a = np.ascontiguousarray(arrays[k])
        h.update(json.dumps([k, a.dtype.str, list(a.shape)]).encode())
        h.update(a.tobytes())
    return h.hexdigest()
