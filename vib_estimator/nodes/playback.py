# Copyright 2026 vib_estimator developers
# SPDX-License-Identifier: Apache-2.0
"""The bag replayer's schedule, without ROS: when each recorded message is due.

:class:`Playback` maps a steady (monotonic) clock to the bag's log-time axis::

    bag_time = anchor_bag + (now - anchor_wall) * rate

and hands out the messages whose log time has been reached. Pausing, resuming, changing the rate,
``play_next`` and looping move the anchors; while paused the bag time stands still. The node
(:mod:`vib_estimator.nodes.bag_replayer`) only asks it, every tick, which messages are due and
publishes them, and publishes :meth:`Playback.bag_time_ns` on ``/clock``.

:class:`StartGate` decides when playing begins: not before ``delay`` has passed, and not before
every played topic has a subscriber -- or ``wait_timeout`` has passed since the replayer started
(``wait_timeout = 0``: do not wait). All times are integer nanoseconds of the caller's steady
clock.
"""

from __future__ import annotations

from typing import Callable, Iterator, Optional, Protocol

from ..errors import EmptyPlayback


class Message(Protocol):
    """What the schedule needs of a recorded message (``vib_estimator.io.bags.BagMessage``)."""

    log_time_ns: int


#: once one played topic has a subscriber, the others get this long to match too (a consumer's
#: subscriptions are discovered together, within tens of ms), s; a topic nobody subscribes to
#: never holds the others back longer
SETTLE_S = 0.5


class StartGate:
    """When to begin playing: after ``delay_s``, and once every played topic has a subscriber,
    or :data:`SETTLE_S` after the first one has, or when ``wait_timeout_s`` (counted from
    ``now_ns``, concurrently with the delay) has passed with none."""

    def __init__(self, now_ns: int, delay_s: float, wait_timeout_s: float) -> None:
        self.not_before_ns = now_ns + int(round(delay_s * 1e9))
        self.deadline_ns = now_ns + int(round(wait_timeout_s * 1e9))
        #: set when the gate opened on the timeout, with subscribers still missing
        self.timed_out = False
        #: set when the gate opened with some played topics still without a subscriber
        self.partial = False
        self._first_match_ns: Optional[int] = None

    def is_open(self, now_ns: int, subscribers_matched: bool, any_matched: bool = False) -> bool:
        """Whether playing may begin at ``now_ns`` (``subscribers_matched``: every played topic
        has a subscriber; ``any_matched``: at least one has); sets :attr:`timed_out` or
        :attr:`partial` when it opens with subscribers missing."""
        if any_matched and self._first_match_ns is None:
            self._first_match_ns = now_ns
        if now_ns < self.not_before_ns:
            return False
        if subscribers_matched:
            return True
        if self._first_match_ns is not None and now_ns >= self._first_match_ns + int(
            SETTLE_S * 1e9
        ):
            self.partial = True
            return True
        if now_ns >= self.deadline_ns:
            self.timed_out = True
            return True
        return False


class Playback:
    """The schedule of one bag (see the module docstring).

    Args:
        open_messages: returns a fresh iterator over the messages to play, from ``first_ns`` on,
            in log-time order (called again at each loop).
        first_ns: log time at which playing starts (the bag's start plus ``start_offset``).
        rate: speed factor (> 0).
        loop: start over at the end instead of finishing.
        paused: start paused.
        loop_gap_ns: bag time between the last message and the first one again when looping
            (the node gives one mean message spacing, so a one-message bag is not replayed at
            every tick).

    Raises :class:`EmptyPlayback` when ``open_messages()`` yields nothing.
    """

    def __init__(
        self,
        open_messages: Callable[[], Iterator[Message]],
        first_ns: int,
        rate: float = 1.0,
        loop: bool = False,
        paused: bool = False,
        loop_gap_ns: int = 0,
    ) -> None:
        self._open = open_messages
        self.loop_gap_ns = max(0, int(loop_gap_ns))
        self.first_ns = first_ns
        self.rate = rate
        self.loop = loop
        self.paused = paused
        #: set by :meth:`start`; nothing is due before
        self.started = False
        #: set at the end of the bag when not looping
        self.finished = False
        #: times the bag started over
        self.loops = 0
        self._anchor_bag = first_ns
        self._anchor_wall = 0
        self._rewind()

    def _rewind(self) -> None:
        self._messages = self._open()
        self.next: Optional[Message] = next(self._messages, None)
        if self.next is None:
            raise EmptyPlayback('no message to play after start_offset')

    def _anchor(self, bag_ns: int, wall_ns: int) -> None:
        self._anchor_bag, self._anchor_wall = bag_ns, wall_ns

    def start(self, now_ns: int) -> None:
        """Begin playing: the bag time so far (``first_ns``, or the last ``play_next``) is now."""
        self._anchor(self._anchor_bag, now_ns)
        self.started = True

    def bag_time_ns(self, now_ns: int) -> int:
        """Playback time on the bag's log-time axis at steady time ``now_ns``."""
        elapsed = now_ns - self._anchor_wall
        if self.paused or not self.started or elapsed <= 0:
            return self._anchor_bag
        return self._anchor_bag + int(elapsed * self.rate)

    def _advance(self) -> Message:
        message = self.next
        self.next = next(self._messages, None)
        return message

    def due(self, now_ns: int) -> Iterator[Message]:
        """Yield, in order, every message whose log time has been reached at ``now_ns``; at the
        end of the bag, start over (``loop``) or set :attr:`finished`."""
        if not self.started or self.paused or self.finished:
            return
        bag_now = self.bag_time_ns(now_ns)
        while self.next is not None and self.next.log_time_ns <= bag_now:
            yield self._advance()
        if self.next is None:
            if self.loop:
                self._rewind()
                self._anchor(self.first_ns - self.loop_gap_ns, now_ns)
                self.loops += 1
            else:
                self.finished = True

    def set_rate(self, rate: float, now_ns: int) -> None:
        """Change the speed from now on (the bag time does not jump)."""
        self._anchor(self.bag_time_ns(now_ns), now_ns)
        self.rate = rate

    def pause(self, now_ns: int) -> bool:
        """Stop the bag time where it is; False if already paused."""
        if self.paused:
            return False
        self._anchor(self.bag_time_ns(now_ns), now_ns)
        self.paused = True
        return True

    def resume(self, now_ns: int) -> bool:
        """Let the bag time run again from where it stopped; False if not paused."""
        if not self.paused:
            return False
        self.paused = False
        self._anchor(self._anchor_bag, now_ns)
        return True

    def play_next(self, now_ns: int) -> Optional[Message]:
        """While paused: the next message at once (the bag time moves to its log time); None if
        not paused or none is left."""
        if not self.paused or self.next is None:
            return None
        message = self._advance()
        self._anchor(message.log_time_ns, now_ns)
        return message
