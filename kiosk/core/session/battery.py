"""A battery: the instruments of one visit, given one after another, each by its own
:class:`~kiosk.core.session.Session`.

Why one session per instrument: each instrument's result stays separate without a single line
of the session knowing about batteries (its own stored session, response, total, band and
Observation, synced to the station as today), and a crash loses at most the instrument that was
running. What the sessions of a visit share is passed on from one to the next: the patient, the
language, who answers, how the visit began, the clock, the store, the live adaptation and, for
the QoS, the engine and its trace (one list), with session time continuing where the previous
instrument stopped. So the engine's state carries across instruments and the visit has ONE
trace. An instrument with its own RoQME model (``qos_model:``) gets an engine of that model and
that engine's trace: one engine per model, one trace per model, each continuous over the
instruments using it (see ARCHITECTURE.md, "A battery").

Only the first instrument has the practice questions; each later one opens with the rest screen
(:attr:`~kiosk.core.session.Phase.REST`), then its explanation. The session logs its
:class:`~kiosk.core.session.state.BatteryPlace` at the start, so a continued test knows which
instruments are still to come (:meth:`Battery.place_of`).

A visit's ``steps`` may also name the Timed Up and Go (:data:`TUG`, issue 34): it has no session
(the app runs it between sessions, :mod:`kiosk.core.tug.visit`), but it holds its place in the
order, so a place counts it ("2/3 barthel,tug,lawton") and :meth:`Battery.tug_after` says when it
is due.
"""

from __future__ import annotations

import uuid
from collections.abc import Callable, Hashable, Iterable, Mapping, Sequence
from dataclasses import field
from typing import Any

from basis import record
from kiosk.core.questionnaire import Questionnaire
from kiosk.core.session.core import Session
from kiosk.core.session.ports import QosEngine
from kiosk.core.session.state import BatteryPlace
from kiosk.core.visits import TUG


@record
class Instrument:
    """One instrument of a battery: its questionnaire and the RoQME model its QoS runs on (None:
    the kiosk's model). ``model`` is whatever ``make_engine`` takes."""

    questionnaire: Questionnaire
    model: Hashable | None = None


@record(frozen=False)
class _Qos:
    engine: QosEngine | None
    trace: list[dict[str, Any]] = field(default_factory=list)


class Battery:
    """The instruments of one visit, in order, and the sessions that give them.

    ``make_engine(model)`` builds a QoS engine for a model (``None``: the kiosk's model; it may
    return None for no QoS). ``shared`` are the :class:`Session` keywords every instrument's
    session gets (``clock``, ``store``, ``timing``, ``adaptation``, ``next_patient_after_s``...).
    ``visit_id`` names the visit (a new one by default). ``steps``: the visit's ids in order, the
    instruments' and :data:`TUG` among them (default: the instruments' ids).
    """

    def __init__(
        self,
        instruments: Sequence[Instrument],
        *,
        make_engine: Callable[[Hashable | None], QosEngine | None],
        shared: Mapping[str, Any],
        visit_id: str | None = None,
        steps: Sequence[str] | None = None,
    ) -> None:
        if not instruments:
            raise ValueError("a battery needs at least one instrument")
        self.instruments = tuple(instruments)
        given = [i.questionnaire.id for i in self.instruments]
        self.steps = tuple(steps) if steps else tuple(given)
        if [s for s in self.steps if s != TUG] != given:
            raise ValueError(f"steps {self.steps} are not the instruments {given} (and {TUG!r})")
        self.visit_id = visit_id or uuid.uuid4().hex[:12]
        self._make_engine = make_engine
        #: the keywords every instrument's session gets
        self.shared = dict(shared)
        self._qos: dict[Hashable | None, _Qos] = {}

    @property
    def ids(self) -> tuple[str, ...]:
        """The visit's steps, in order: the instruments' ids (and :data:`TUG` where it comes)."""
        return self.steps

    def _instrument(self, step: int) -> int:
        """The index among the instruments of the instrument at ``step``."""
        return step - sum(1 for s in self.steps[:step] if s == TUG)

    def _next_instrument(self, step: int) -> int | None:
        """The step of the first instrument at or after ``step`` (None: none is left)."""
        return next((i for i in range(step, len(self.steps)) if self.steps[i] != TUG), None)

    def tug_after(self, session: Session | None) -> int | None:
        """The step of a Timed Up and Go due after ``session`` (None: before the first
        instrument) and before the next instrument, or None when none is."""
        if session is None:
            step = 0
        elif (place := session.battery) is not None and place.visit_id == self.visit_id:
            step = place.index + 1
        else:
            return None
        return step if step < len(self.steps) and self.steps[step] == TUG else None

    def place(self, index: int) -> BatteryPlace:
        return BatteryPlace(self.visit_id, index, self.ids)

    def qos(self, index: int) -> tuple[QosEngine | None, list[dict[str, Any]]]:
        """The engine and trace the session at step ``index`` uses (made on first use); a TUG's
        step uses the kiosk's model's."""
        model = None if self.steps[index] == TUG else self.instruments[self._instrument(index)].model
        if model not in self._qos:
            self._qos[model] = _Qos(self._make_engine(model))
        found = self._qos[model]
        return found.engine, found.trace

    def first(self, **kwargs: Any) -> Session:
        """The first instrument's session (``kwargs``: ``patient_id``, ``language``, ``visit``...)."""
        first = self._next_instrument(0)
        assert first is not None  # the instruments are not empty
        return self._session(first, kwargs)

    def after(self, session: Session) -> Session | None:
        """The session of the instrument after ``session``'s (None after the last, or for a
        session of another battery). It continues the visit: same patient, language, answerer and
        visit, session time going on from ``session``'s now, and no practice questions."""
        place = session.battery
        step = None if place is None or place.visit_id != self.visit_id else self._next_instrument(place.index + 1)
        if step is None:
            return None
        session.out.let_go_of_engine()
        return self._session(
            step,
            {
                "patient_id": session.patient_id,
                "language": session.language,
                "answered_by": session.answered_by,
                "visit": session.visit,
                "answerer": session.opening.answerer,
                "t_offset": session.now(),
                "familiarisation": False,
            },
        )

    def resume(self, stored: Any, before: Iterable[Any] = ()) -> Session:
        """The session continuing ``stored`` (a ``StoredSession`` of this battery's visit, see
        :meth:`place_of`). ``before``: the visit's earlier instruments' stored sessions, oldest
        first, whose traces are replayed into their engines first so the QoS goes on from where
        the whole visit was, and whose trace the continued trace extends."""
        place = self.place_of(stored)
        assert place is not None and place.visit_id == self.visit_id
        for earlier in before:
            earlier_place = self.place_of(earlier)
            if earlier_place is None:
                continue
            engine, trace = self.qos(earlier_place.index)
            for event in earlier.trace:
                if engine is not None:
                    engine.update(event["t"], set=event.get("set") or {}, emit=list(event.get("emit") or []))
                trace.append(dict(event))
        engine, trace = self.qos(place.index)
        session = Session.from_stored(
            self.instruments[self._instrument(place.index)].questionnaire,
            stored,
            engine=engine,
            battery=place,
            **self.shared,
        )
        trace.extend(session.out.trace)
        session.out.trace = trace
        return session

    @staticmethod
    def place_of(stored: Any) -> BatteryPlace | None:
        """Where a stored session stands in its battery (None: not part of one)."""
        detail = next((entry.detail for entry in stored.log if entry.kind == "battery"), None)
        return BatteryPlace.parse(detail) if detail else None

    def _session(self, index: int, kwargs: Mapping[str, Any]) -> Session:
        engine, trace = self.qos(index)
        options = {**self.shared, **kwargs}
        # a battery of one is a plain session, logged as sessions always were
        place = self.place(index) if len(self.steps) > 1 else None
        questionnaire = self.instruments[self._instrument(index)].questionnaire
        session = Session(questionnaire, engine=engine, battery=place, **options)
        session.out.trace = trace  # one trace per engine: the visit's, across its instruments
        return session
