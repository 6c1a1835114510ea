"""A recogniser wrapper that adds up the processor time it takes, for ``bench/asr.py``."""

from __future__ import annotations

import time


class Timed:
    """Adds up the processor time a recogniser spends (process time, not wall time: the bench
    shares its cores with other work, which would otherwise count as the recogniser's)."""

    def __init__(self, inner) -> None:
        self.inner, self.seconds, self.name, self.language = inner, 0.0, inner.name, inner.language
        #: processor seconds of the latest finish(): the endpoint → result part of the latency
        self.last_finish = 0.0
        #: utterances finished
        self.finished = 0

    def set_grammar(self, *args, **kwargs):
        """Forward."""
        return self.inner.set_grammar(*args, **kwargs)

    def reset(self) -> None:
        """Forward."""
        self.inner.reset()

    def accept(self, pcm: bytes):
        """Forward, timed."""
        began = time.process_time()
        try:
            return self.inner.accept(pcm)
        finally:
            self.seconds += time.process_time() - began

    def finish(self):
        """Forward, timed."""
        began = time.process_time()
        try:
            return self.inner.finish()
        finally:
            self.last_finish = time.process_time() - began
            self.seconds += self.last_finish
            self.finished += 1
