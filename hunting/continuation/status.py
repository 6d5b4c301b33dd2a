"""Outcome codes of the periodic-orbit methods: the cycle search, shooting and continuation.

The integrator's :class:`hunting.Status` says what happened to one integration; these codes
say what happened to the search for an orbit, with advice on what to change. Values start at
100 so that they never read as an integrator status.
"""
from __future__ import annotations

import enum


class OrbitStatus(enum.IntEnum):
    """Outcome of :func:`find_cycle`, :func:`shoot` and :func:`continue_orbit`.

    Examples
    --------
    >>> from hunting.continuation import OrbitStatus
    >>> OrbitStatus.EQUILIBRIUM.ok
    False
    >>> OrbitStatus.SUCCESS.ok
    True
    """

    SUCCESS = 0               #: converged (shooting, cycle search) / reached the end of the range (continuation)
    NO_RECURRENCE = 101       #: the transient never returned to a section, or its returns did not repeat
    EQUILIBRIUM = 102         #: the motion came to rest, or shooting converged to a rest point
    ESCAPE = 103              #: the state grew without bound during the transient
    SINGULAR_JACOBIAN = 104   #: the shooting Jacobian is singular
    NOT_CONVERGED = 105       #: Newton did not reach the tolerance within its bounds
    INTEGRATION_FAILED = 106  #: an integration needed by the method ended with an integrator failure
    POINT_LIMIT = 107         #: continuation stopped at max_points
    STEP_LIMIT = 108          #: continuation's corrector failed down to the smallest step
    NO_START = 109            #: no starting cycle for continuation
    NO_CYCLE = 110            #: the event map has no cycle of the kind asked for

    @property
    def ok(self) -> bool:
        return self == OrbitStatus.SUCCESS

    @property
    def advice(self) -> str:
        """What the code means and what to change."""
        return _ADVICE[self]


_ADVICE = {
    OrbitStatus.SUCCESS: "converged",
    OrbitStatus.NO_RECURRENCE: ("the motion did not return periodically within the transient bound: start "
                                "closer to the cycle (x0), give period_guess, or raise t_max"),
    OrbitStatus.EQUILIBRIUM: ("the motion came to rest (an equilibrium or the stick set attracts this start): "
                              "start with a larger deviation (x0) or change the parameters"),
    OrbitStatus.ESCAPE: ("the state grew without bound: the loop is unstable at these parameters "
                         "(no bounded cycle from this start)"),
    OrbitStatus.SINGULAR_JACOBIAN: ("the shooting Jacobian is singular: the orbit is not isolated (a family "
                                    "of cycles, e.g. a conserved quantity), grazes a switching surface, or the "
                                    "section is tangent to the flow; start from another point of the orbit"),
    OrbitStatus.NOT_CONVERGED: ("Newton did not converge: improve the guess (x0, period_guess) or loosen tol"),
    OrbitStatus.INTEGRATION_FAILED: ("an integration failed (see the integrator's status in the message): "
                                     "adjust the integration options or the parameters"),
    OrbitStatus.POINT_LIMIT: "the branch reached max_points: raise max_points or ds_max",
    OrbitStatus.STEP_LIMIT: ("the corrector failed down to the smallest step: a sharp turn, a grazing point or "
                             "the end of the branch; lower ds_min or restart past this point"),
    OrbitStatus.NO_START: "no starting cycle was found at the first parameter value",
    OrbitStatus.NO_CYCLE: ("the event map has no cycle of this kind on the searched range: widen it (d_max), "
                           "or change the parameters"),
}
