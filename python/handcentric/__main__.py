"""`python -m handcentric`: the in-process audit of a representation or a policy written in
Python, from the shell.

    python -m handcentric audit my_repr.py:actions --observation my_repr.py:observation
    python -m handcentric audit-policy my_package.policies:policy --group se3 --cases 500
    python -m handcentric conventions --detect episodes.npz

MODULE:FUNCTION names the callable: MODULE is a dotted module name (importable from the current
directory or sys.path) or the path of a .py file (its folder is put on sys.path, so that it
imports its neighbours); FUNCTION may be dotted (Class.method). The callables take what
handcentric.audit and handcentric.audit_policy pass them (help(handcentric.audit)).

Prints one line per verdict (view, component, mode, group, yes/NO, largest error) and exits 0;
--json prints the full result instead (the dict handcentric.audit / audit_policy returns, as
JSON). The options are spelled as `handcentric audit` spells them (--group, --view, --json).
Bad arguments: one line on stderr, exit 2. An exception raised by the callable under audit
propagates with its traceback (exit 1)."""
import argparse
import importlib
import importlib.util
import json
import os
import sys

import handcentric

PROG = "python -m handcentric"


class BadTarget(Exception):
    """MODULE:FUNCTION names nothing callable (a usage error; not LookupError, which the
    callable under audit may raise itself)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        # One line, as the C++ command's usage errors (README.md: "a usage error exits 2").
        self.exit(2, "%s: error: %s (see --help)\n" % (self.prog, message))


class _Deprecated(argparse.Action):
    """An old spelling, kept for one release: it works as the new one and says so on stderr."""

    def __init__(self, option_strings, dest, new, **kwargs):
        self.new = new
        super().__init__(option_strings, dest, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        print("%s: %s is deprecated: use %s (the same values, as `handcentric audit` spells it); "
              "the old name goes in the next release" % (PROG, option_string, self.new),
              file=sys.stderr)
        setattr(namespace, self.dest, values)


def _bounded(low, high):
    def parse(text):
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError("not an integer: %r" % text) from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError("%d is not in %d..%d" % (value, low, high))
        return value
    return parse


def _load_module(spec):
    if spec.endswith(".py") or os.sep in spec:
        path = os.path.abspath(spec)
        if not os.path.isfile(path):
            raise BadTarget("no such file: %s" % spec)
        folder, name = os.path.split(path)
        name = os.path.splitext(name)[0]
        if name in sys.modules and getattr(sys.modules[name], "__file__", None) == path:
            return sys.modules[name]
        sys.path.insert(0, folder)
        loader = importlib.util.spec_from_file_location(name, path)
        module = importlib.util.module_from_spec(loader)
        sys.modules[name] = module  # before running it, as `import` does
        loader.loader.exec_module(module)
        return module
    if "" not in sys.path and os.getcwd() not in sys.path:
        sys.path.insert(0, os.getcwd())
    try:
        return importlib.import_module(spec)
    except ModuleNotFoundError as e:
        if e.name and spec.split(".")[0] == e.name.split(".")[0]:
            raise BadTarget("no module named %r" % e.name) from None
        raise  # the module exists and failed to import something itself: its traceback


def load_attribute(text):
    """The object named by MODULE:NAME (NAME may be dotted); BadTarget with a one-line reason
    otherwise."""
    module_name, colon, attribute = text.rpartition(":")
    if not colon or not module_name or not attribute:
        raise BadTarget("%r is not MODULE:FUNCTION" % text)
    value = _load_module(module_name)
    for part in attribute.split("."):
        try:
            value = getattr(value, part)
        except AttributeError:
            raise BadTarget("%s has no %r" % (module_name, attribute)) from None
    return value


def load_callable(text):
    """The callable named by MODULE:FUNCTION; BadTarget with a one-line reason otherwise."""
    value = load_attribute(text)
    if not callable(value):
        raise BadTarget("%s is not callable" % text)
    return value


def _frequency(text):
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError("not a number: %r" % text) from None
    if not 0.0 < value < 1.0:
        raise argparse.ArgumentTypeError("%s is not a frequency in (0, 1)" % text)
    return value


def _detect_option(sub):
    sub.add_argument("--detect", type=_frequency, metavar="F",
                     help="instead of --cases, as many cases as find a breaking on a share F of "
                          "the (scene, g) draws with 99%% probability (detect=F; 0.01: 459 "
                          "cases)")


def make_parser():
    parser = _Parser(prog=PROG, description=__doc__,
                     formatter_class=argparse.RawDescriptionHelpFormatter,
                     epilog="Each subcommand has its own --help. What the verdicts mean: "
                            "docs/AUDIT.md; from Python: docs/AUDIT_YOUR_POLICY.md.")
    parser.add_argument("--version", action="version", version=handcentric.__version__)
    commands = parser.add_subparsers(dest="command", required=True, metavar="COMMAND",
                                     parser_class=_Parser)

    def common(sub, what):
        sub.add_argument("target", metavar="MODULE:FUNCTION", help=what)
        # Spelled as `handcentric audit` spells them; --groups and --views are the old names.
        sub.add_argument("--group", nargs="+", choices=handcentric.GROUPS + ("all",),
                         metavar="GROUP", dest="groups",
                         help="one or more of %s, or all (the default)"
                              % ", ".join(handcentric.GROUPS))
        sub.add_argument("--view", nargs="+", choices=handcentric.VIEWS + ("all",),
                         metavar="VIEW", dest="views",
                         help="one or both of %s, or all (the default)"
                              % ", ".join(handcentric.VIEWS))
        for old, new, names in (("--groups", "--group", handcentric.GROUPS),
                                ("--views", "--view", handcentric.VIEWS)):
            sub.add_argument(old, nargs="+", dest=old[2:], choices=names + ("all",),
                             action=_Deprecated, new=new, help=argparse.SUPPRESS)
        sub.add_argument("--cases", type=_bounded(1, handcentric.MAX_CASES), metavar="N",
                         help="cases per check, 1 to %d" % handcentric.MAX_CASES)
        sub.add_argument("--seed", type=int, metavar="S",
                         help="seeds all the audit draws: the cases, a policy's noise, the "
                              "in-distribution draws (default 1)")
        sub.add_argument("--precision", choices=("float64", "float32", "bfloat16", "float16"),
                         help="the arithmetic of the callable, for the tolerance "
                              "(default float64)")
        sub.add_argument("--batch-size", type=_bounded(1, handcentric.MAX_BATCH_SIZE),
                         metavar="B",
                         help="call the callable on stacked arrays of up to B scenes "
                              "(batch_size=B; the same verdicts, fewer calls)")
        sub.add_argument("--array", choices=("numpy", "torch"),
                         help="the callable's arguments: NumPy arrays (default) or torch tensors")
        sub.add_argument("--device", metavar="DEVICE",
                         help="the torch device of the arguments (with --array torch)")
        for name, low, what in (("history", 0, "past poses H"),
                                ("hand-points", 0, "eye-in-hand points n"),
                                ("world-points", 1, "world points m of the third-person view")):
            sub.add_argument("--" + name, type=_bounded(low, 64), metavar="N",
                             help="fix the number of %s (default: drawn per case)" % what)
        sub.add_argument("--quiet", action="store_true", default=None,
                         help="no progress line on stderr")
        sub.add_argument("--json", nargs="?", const="-", metavar="FILE",
                         help="print the whole result as JSON instead of the lines, as "
                              "`handcentric audit --json` does (--json FILE, which also wrote "
                              "FILE, is the old form)")

    audit = commands.add_parser(
        "audit", help="audit a representation (handcentric.audit)",
        description="Audit a representation written in Python (handcentric.audit): which "
                    "groups leave its actions, observation and flow invariant.")
    common(audit, "the actions function (history, chunk, hand_points, world_points) -> 1-D")
    _detect_option(audit)
    audit.add_argument("--observation", metavar="MODULE:FUNCTION",
                       help="the observation function (history, hand_points, world_points)")
    audit.add_argument("--chunk", type=_bounded(1, 64), metavar="K",
                       help="fix the chunk length K (default: drawn per case)")
    audit.add_argument("--decode", metavar="MODULE:FUNCTION",
                       help="the decoder (actions, history, hand_points, world_points) -> "
                            "(K, 4, 4)")
    policy = commands.add_parser(
        "audit-policy", help="audit a whole policy, eq. (4) (handcentric.audit_policy)",
        description="Audit a whole policy (handcentric.audit_policy): a(g o, n) = g a(o, n), "
                    "pointwise and in distribution.")
    common(policy, "the policy (history, hand_points, world_points, noise) -> (K, 4, 4)")
    _detect_option(policy)
    policy.add_argument("--noise", type=_bounded(1, handcentric.MAX_NOISE), metavar="N",
                        help="standard normals per call, 1 to %d" % handcentric.MAX_NOISE)
    policy.add_argument("--rng", choices=("torch", "numpy", "generator"),
                        help="the policy draws its own random numbers from this generator: seed "
                             "it alike for o and g o (rng=; one observation per call)")
    policy.add_argument("--reset", metavar="MODULE:FUNCTION",
                        help="a function of no arguments called before every call of the policy "
                             "(reset=; e.g. a policy's reset, for one that keeps state)")
    where = commands.add_parser(
        "locate", help="where a policy breaks the symmetry (handcentric.locate)",
        description="The first module of a torch policy, or the first stage of a pipeline, "
                    "whose output is not invariant (not equivariant for outputs declared "
                    "poses), on the audit's pointwise cases (docs/AUDIT.md, \"Localizing a "
                    "break\"). MODULE:NAME is a policy with --module, or a list of (name, "
                    "callable) stages.")
    common(where, "a policy (history, hand_points, world_points, noise) -> (K, 4, 4) with "
                  "--module, or a list of (name, callable) stages")
    where.add_argument("--module", metavar="ATTRIBUTE",
                       help="the torch module the policy calls, as an attribute of the policy "
                            "(e.g. net, or model.encoder)")
    where.add_argument("--kinds", metavar="KINDS",
                       help="features (invariant, the default) or poses (world-frame poses, "
                            "equivariant): NAME=KIND,... or, for stages, one KIND per stage "
                            "(poses,poses,features)")
    where.add_argument("--noise", type=_bounded(1, handcentric.MAX_NOISE), metavar="N",
                       help="standard normals per call, 1 to %d" % handcentric.MAX_NOISE)
    where.add_argument("--rng", choices=("torch", "numpy", "generator"),
                       help="seed the policy's own draws alike for o and g o (rng=)")
    conventions = commands.add_parser(
        "conventions", help="which convention recorded episodes are in "
                            "(handcentric.detect_convention)",
        description="Rank every convention of conventions/ and every pose layout by how well "
                    "it decodes recorded episodes, as `handcentric conventions --detect` does.")
    conventions.add_argument("--detect", metavar="FILE", required=True,
                             help="a .npz (arrays state, action, episode) or .jsonl (one "
                                  "object per line with those keys)")
    conventions.add_argument("--plugins", metavar="DIR",
                             help="the folder of convention plug-ins (default: the source "
                                  "tree's conventions/)")
    conventions.add_argument("--declared", metavar="LAYOUT",
                             help="the layout the data are believed in (flagged if they "
                                  "contradict it)")
    conventions.add_argument("--json", action="store_true",
                             help="the ranking as JSON (the dicts detect_convention returns)")
    return parser


def _detect(args):
    """`conventions --detect`: the ranking, or a bad input as one line and exit 1."""
    from . import detect
    argv = [args.detect] + (["--plugins", args.plugins] if args.plugins else []) + \
        (["--declared", args.declared] if args.declared else []) + \
        (["--json"] if args.json else []) + ["--audit"]
    return detect.main(argv, prog=PROG + " conventions --detect")


def _kinds(text):
    """--kinds: NAME=KIND,... as a dict, or KIND,KIND,... as a list; None when not given."""
    if not text:
        return None
    items = [item.strip() for item in text.split(",")]
    if all("=" in item for item in items):
        return dict(item.split("=", 1) for item in items)
    if any("=" in item for item in items):
        raise BadTarget("--kinds mixes NAME=KIND and KIND: %r" % text)
    return items


def _locate(args, keywords):
    """handcentric.locate on the target: a policy with --module, else a list of stages."""
    for option in ("groups", "views"):
        if option in keywords:
            if len(keywords[option]) != 1:
                raise BadTarget("locate looks at one %s at a time, got %s"
                                % (option[:-1], " ".join(keywords[option])))
            keywords[option[:-1]] = keywords.pop(option)[0]
    if args.json not in (None, "-"):
        raise BadTarget("locate writes its JSON to stdout: --json > %s" % args.json)
    kinds = _kinds(args.kinds)
    target = load_attribute(args.target)
    if args.module:
        if not callable(target):
            raise BadTarget("%s is not callable" % args.target)
        module = target
        for part in args.module.split("."):
            try:
                module = getattr(module, part)
            except AttributeError:
                raise BadTarget("%s has no attribute %r" % (args.target, args.module)) from None
        return handcentric.locate(target, module=module, kinds=kinds, **keywords)
    if callable(target) or not isinstance(target, (list, tuple)):
        raise BadTarget("%s is a policy: name its torch module with --module, or give a list "
                        "of (name, callable) stages" % args.target)
    return handcentric.locate(stages=target, kinds=kinds, **keywords)


def _keywords(args):
    """Only the options given: the module's defaults stay the single source of the others."""
    out = {}
    for option in ("groups", "views", "cases", "seed", "precision", "batch_size", "noise",
                   "array", "device", "history", "hand_points", "world_points", "chunk",
                   "quiet", "rng", "detect"):
        value = getattr(args, option, None)
        if option in ("groups", "views") and value and "all" in value:
            value = None  # all: the module's default
        if value is not None:
            out[option] = tuple(value) if isinstance(value, list) else value
    return out


def _error_text(error):
    value = error.get("max_error") if isinstance(error, dict) else error
    if value is None:
        return "-"
    return value if isinstance(value, str) else "%.3g" % value


def summary_lines(result):
    """One line per verdict of an audit's result, plus a header (and injectivity when given)."""
    checks = result.get("checks", [])
    # A representation's checks name their component; a policy's have one verdict per cell.
    components = any("component" in check for check in checks)
    header = ("view",) + (("component",) if components else ()) + (
        "mode", "group", "holds", "largest error")
    rows = []
    for check in checks:
        verdict = check.get("invariant", check.get("equivariant"))
        rows.append((check.get("view", "-"),) + ((check.get("component", "-"),) if components
                                                 else ()) +
                    (check.get("mode", "-"), check.get("group", "-"),
                     "yes" if verdict else "NO", _error_text(check)))
    widths = [max(len(str(row[i])) for row in [header] + rows) for i in range(len(header))]
    lines = ["  ".join(str(cell).ljust(width) for cell, width in zip(row, widths)).rstrip()
             for row in [header] + rows]
    if "injective" in result:
        lines.append("injective: %s" % ("yes" if result["injective"] else "NO"))
    preflight = result.get("preflight") or {}
    if preflight.get("note"):
        lines.append("no pointwise verdict: %s" % preflight["note"])
    return lines


def main(argv=None):
    parser = make_parser()
    args = parser.parse_args(argv)
    if args.command == "conventions":
        return _detect(args)
    try:
        keywords = _keywords(args)
        if args.command == "locate":
            return _print_location(_locate(args, keywords), args)
        target = load_callable(args.target)
        if args.command == "audit":
            for option in ("observation", "decode"):
                if getattr(args, option):
                    keywords[option] = load_callable(getattr(args, option))
            result = handcentric.audit(target, **keywords)
        else:
            if args.reset:
                keywords["reset"] = load_callable(args.reset)
            result = handcentric.audit_policy(target, **keywords)
    except BadTarget as e:
        parser.error(str(e))
    except (handcentric.Error, handcentric.ShapeError) as e:
        # Wrong shapes, bad tolerances and the like: the module's message is the diagnosis.
        print("%s: %s" % (PROG, e), file=sys.stderr)
        return 1
    if args.json == "-":
        try:
            sys.stdout.write(json.dumps(result, indent=1) + "\n")
            sys.stdout.flush()
        except BrokenPipeError:  # `| head`: the reader has what it wanted
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0
    name = result.get("name", args.target)
    print("%s %s (%s)" % (args.command, name, args.target))
    for line in summary_lines(result):
        print("  " + line)
    if args.json:
        print("%s: --json FILE is deprecated: use --json > FILE (the JSON on stdout, as "
              "`handcentric audit --json`); the FILE form goes in the next release" % PROG,
              file=sys.stderr)
        with open(args.json, "w") as out:
            json.dump(result, out, indent=1)
            out.write("\n")
    return 0


def _print_location(result, args):
    """locate's table, or with --json its JSON, on stdout."""
    try:
        if args.json == "-":
            sys.stdout.write(handcentric.locate_json(result, indent=1) + "\n")
        else:
            sys.stdout.write(handcentric.locate_text(result) + "\n")
        sys.stdout.flush()
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    return 0


if __name__ == "__main__":
    sys.exit(main())
