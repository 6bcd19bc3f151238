"""Videos of the tested policy during training (``--set video_every=N``; SB3's ``VecVideoRecorder``,
CleanRL's ``--capture-video``): every ``N`` generations the run loop checkpoints and :class:`VideoCallback`
renders the best policy so far, one test episode as ``shaped-es render`` does, into
``RUN/videos/gen_NNNNNN.gif``. An env that cannot render stops the run in one line before its first
generation. Videos change no result: they read the checkpoint and roll out on evaluation seeds.
"""

from __future__ import annotations

import sys

from shaped_es.monitor.callbacks import Callback, as_callbacks
from shaped_es.trained.render import check_renders, render_run


class VideoCallback(Callback):
    def __init__(self, progress: bool = False):
        self.progress = progress

    def on_start(self, run) -> None:
        super().on_start(run)
        check_renders(run.cfg.env, run.cfg.env_kwargs)

    def on_checkpoint(self, generation: int) -> None:
        out = self.run.store.root / "videos" / f"gen_{generation:06d}.gif"
        res = render_run(self.run.store.root, out, which="best")
        if self.progress:
            print(f"[{self.run.label}] video of the best policy (return {res['returns'][0]:.2f}): {out}",
                  file=sys.stderr, flush=True)


def with_video(cfg, callback=None, progress: bool = False) -> list[Callback]:
    """``callback`` as a list, with a :class:`VideoCallback` when ``cfg.video_every`` is set."""
    out = as_callbacks(callback)
    return out + [VideoCallback(progress)] if cfg.video_every is not None else out
