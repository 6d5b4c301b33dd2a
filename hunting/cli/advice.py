"""The library's advice, told in the command line's words.

Status and error messages are written for the Python API ("give period_guess, or raise
t_max", "use method='radau'"). A command-line user needs the option that does it
(``--period-guess``, ``--t-max``, ``--method radau``), or, where the command has no such
option, to be told that only the Python API sets it. :func:`for_cli` rewrites a message for
one command: each known advice phrase becomes its command-line form, built from the options
that command really has. An advice sentence that a message repeats is kept once.
"""
from __future__ import annotations

import re
from dataclasses import dataclass


@dataclass(frozen=True)
class Command:
    """What a message is rewritten for: the command's name, its option strings and whether
    the system came from a model file (--model)."""

    name: str
    flags: frozenset = frozenset()
    model_file: bool = False

    def has(self, flag: str) -> bool:
        return flag in self.flags


def command_of(args, parser) -> Command:
    """The Command of parsed arguments, with the option strings of their subcommand's parser."""
    sub = parser.commands.get(args.cmd) if hasattr(parser, "commands") else None
    flags = frozenset(s for a in getattr(sub, "_actions", ()) for s in a.option_strings)
    return Command(args.cmd, flags, bool(getattr(args, "model", None)))


def _either(cmd: Command, options: list[tuple[str, str]], none: str) -> str:
    """'a, b or c' of the (flag, phrase) options the command has; ``none`` when it has none."""
    have = [phrase for flag, phrase in options if cmd.has(flag)]
    if not have:
        return none
    return have[0] if len(have) == 1 else ", ".join(have[:-1]) + " or " + have[-1]


def _flags(cmd: Command, *flags: str) -> str:
    """' (--a, --b)' with those of ``flags`` the command has; '' when it has none."""
    have = [f for f in flags if cmd.has(f)]
    return f" ({', '.join(have)})" if have else ""


def _python(what: str) -> str:
    return f"(the command line does not set {what}: use the Python API)"


def _no_recurrence(cmd, m):
    return _either(cmd, [("--x0", "start closer to the cycle (--x0)"), ("--period-guess", "give --period-guess"),
                         ("--t-max", "raise --t-max")],
                   "start where a cycle is easier to find" + _flags(cmd, "--from", "--set"))


def _equilibrium(cmd, m):
    start = "start with a larger deviation (--x0) or " if cmd.has("--x0") else ""
    return f"{start}change the parameters{_flags(cmd, '--set')}"


def _not_converged(cmd, m):
    guess = _either(cmd, [("--x0", "--x0"), ("--period-guess", "--period-guess")], "")
    if guess:
        return f"improve the guess ({guess})"
    return "start from other parameter values" + _flags(cmd, "--from", "--set")


def _d_max(cmd, m):
    return "widen it (--d-max)" if cmd.has("--d-max") else f"widen it {_python('the searched range')}"


def _max_points(cmd, m):
    return _either(cmd, [("--max-points", "raise --max-points"), ("--ds-max", "--ds-max")],
                   ("narrow the range (--from, --to) " if cmd.has("--from") else "") + _python("the point bound"))


def _ds_min(cmd, m):
    if not cmd.has("--from"):
        return f"restart past this point {_python('the smallest step')}"
    return ("lower --ds-min" if cmd.has("--ds-min") else "narrow the range") + " or restart past this point (--from)"


def _max_steps(cmd, m):
    if cmd.has("--max-steps"):
        return "raise --max-steps or loosen --rtol/--atol"
    return f"change the parameters{_flags(cmd, '--set')} {_python('the step bound')}"


def _max_events(cmd, m):
    if cmd.has("--max-events"):
        return "raise --max-events or shorten --t"
    return f"change the parameters{_flags(cmd, '--set')} {_python('the event bound')}"


def _radau(cmd, m):
    return "use --method radau" if cmd.has("--method") else f"use the implicit method radau {_python('the method')}"


def _newton(cmd, m):
    return "loosen --rtol" if cmd.has("--rtol") else f"change the parameters {_python('the tolerance')}"


def _zeno(cmd, m):
    if cmd.model_file:
        return ("check the model file's friction entries: a stick bound or slip law that changes with the state, "
                "or a sign/abs switch inside an equation, makes the motion chatter")
    return f"change the parameters{_flags(cmd, '--set')} or shorten the run"


def _integration(cmd, m):
    opts = _either(cmd, [("--method", "--method"), ("--rtol", "--rtol")], "")
    return f"change the parameters{_flags(cmd, '--set')}" + (f" or the integration ({opts})" if opts else "")


def _growth(cmd, m):
    if cmd.has("--growth"):
        return "if growth is what you study, allow more (a larger --growth, or --growth 0: no check)"
    return "if growth is what you study, run 'hunting simulate --growth 0'"


def _other_point(cmd, m):
    how = _either(cmd, [("--x0", "--x0"), ("--period-guess", "--period-guess")], "")
    return m.group(0) + (f" ({' with '.join(how.split(' or '))})" if how else "")


def _x0_and_guess(cmd, m):
    if cmd.has("--x0") and cmd.has("--period-guess"):
        return "give --x0 and --period-guess"
    return f"give a start and a period guess {_python('them')}"


def _find_cycle(cmd, m):
    return f"{m.group(1)} 'hunting cycle' instead"


# (pattern in the library's text, rewrite(command, match) -> its command-line form); the
# patterns are the advice of hunting.errors, hunting.continuation.status and the event maps
REWRITES = [
    (r"start closer to the cycle \(x0\), give period_guess, or raise t_max", _no_recurrence),
    (r"start with a larger deviation \(x0\) or change the parameters", _equilibrium),
    (r"improve the guess \(x0, period_guess\) or loosen tol", _not_converged),
    (r"widen it \(d_max\)", _d_max),
    (r"raise max_points or ds_max", _max_points),
    (r"lower ds_min or restart past this point", _ds_min),
    (r"raise max_steps or loosen rtol/atol", _max_steps),
    (r"raise max_events or shorten t_span", _max_events),
    (r"use method='radau'", _radau),
    (r"check the Jacobian or loosen rtol", _newton),
    (r"declare a sliding/stick mode for that surface or check the transition function", _zeno),
    (r"adjust the integration options or the parameters", _integration),
    (r"if growth is what you study, allow more \(simulate's growth; None, or --growth 0: no check\)", _growth),
    (r"\b([Uu]se) find_cycle instead", _find_cycle),
    (r"start from another point of the orbit", _other_point),
    (r"give x0 and period_guess", _x0_and_guess),
]
_COMPILED = [(re.compile(p), f) for p, f in REWRITES]

# API option names, as the option of the command when it has one ("max_points = 400 reached"
# -> "--max-points 400 reached"), else in plain words; x0 is left alone ("shooting from x0"
# reads the same either way)
OPTION_WORDS = {"max_points": "the point bound", "ds_min": "the smallest step", "ds_max": "the largest step",
                "max_steps": "the step bound", "max_events": "the event bound", "t_max": "the transient bound",
                "d_max": "the searched range", "period_guess": "a period guess", "rtol": "the tolerance",
                "atol": "the tolerance", "t_span": "the time span"}
_NAMED = re.compile(r"(?<![\w-])(" + "|".join(OPTION_WORDS) + r")\b( = )?")


def _named(cmd: Command, m) -> str:
    flag = "--" + m.group(1).replace("_", "-")
    if cmd.has(flag):
        return flag + (" " if m.group(2) else "")
    return OPTION_WORDS[m.group(1)] + (" " if m.group(2) else "")


def _advice_sentences() -> list[str]:
    """The library's advice texts (long enough that a repetition is a repetition), longest first."""
    return sorted({a for a in library_advice() if len(a) > 40}, key=len, reverse=True)


def library_advice() -> list[str]:
    """Every advice text of the integrator's and the orbit methods' status codes."""
    from ..continuation.status import OrbitStatus
    from ..errors import Status, status_message
    from ..eventmap.family import NOT_A_FAMILY_ADVICE
    return [*(status_message(s) for s in Status), *(s.advice for s in OrbitStatus), NOT_A_FAMILY_ADVICE]


def _once(text: str) -> str:
    """Each advice sentence once: a message that carries its status' advice twice (the cause's
    and the search's) keeps the first (the first letter's case is ignored)."""
    for a in _advice_sentences():
        pat = re.compile("[" + re.escape(a[0].lower() + a[0].upper()) + "]" + re.escape(a[1:]))
        hits = list(pat.finditer(text))
        for h in reversed(hits[1:]):
            start = h.start()
            while start > 0 and text[start - 1] in " .;:,":
                start -= 1
            text = text[:start] + text[h.end():]
    return text


def for_cli(text: str, cmd: Command) -> str:
    """``text`` with each repeated advice sentence once and every API advice phrase in the
    command line's words for ``cmd``."""
    if not text:
        return text
    text = _once(str(text))
    for pat, fn in _COMPILED:
        text = pat.sub(lambda m, fn=fn: fn(cmd, m), text)
    return _NAMED.sub(lambda m: _named(cmd, m), text)


def tell(args, text: str) -> str:
    """:func:`for_cli` for a command's parsed arguments (``args.cli_command``, set by
    :func:`hunting.cli.main`; without it, only the command's name is known)."""
    cmd = getattr(args, "cli_command", None) or Command(getattr(args, "cmd", ""), frozenset(),
                                                        bool(getattr(args, "model", None)))
    return for_cli(text, cmd)
