"""What a translator is given: the goal language described from its node registry, and a key checker.

    .venv/bin/python data/requests/describe_language.py [--language 2] > TRANSLATION_LANGUAGE.md
    .venv/bin/python data/requests/describe_language.py --check "KEY" ["KEY" ...]

The description lists the clause forms, every node type with its parameters, one example
sentence per node type and the notes on words; ``--check`` prints each key's sentence and bits,
or what is wrong with it (a translator's only tool besides this text).
"""

from __future__ import annotations

import argparse
import sys

EXAMPLES = [
    "every all: in-bowl:same", "every all: in-bowl:other", "every all: in-bowl:same-class",
    "every class:warm in-bowl:warm", "every matching:yes in-bowl:same", "every matching:no in-the-bowl:red",
    "every all-but:red on-table:", "every colour:blue on-block:any", "every all: on-block:same-class",
    "exactly-1 all: on-table:", "at-least-2 class:cool on-block:cool", "none all: next-to:a-bowl",
    "every all: next-to:own-bowl", "every all: next-to:block-same-class", "every all: side:left/own-bowl",
    "every class:warm side:front/red block", "every all: region:left half", "every all: region:back strip",
    "every all: region:centre", "every all: region:front left corner", "form row:any all:", "form row:rainbow all:",
    "form row:warm-first all:", "form column:any@left-edge all:", "form tower:any all:",
    "form tower:rainbow@a-corner all:", "form tower:any@by-a-bowl class:warm", "form towers-by-class: all:",
    "form two-towers: all:", "form one-bowl: all:", "form separate-bowls: all:", "form cluster: all:",
    "form cluster:@right-edge class:cool", "form corners: all:", "form each-bowl:1 all:", "form each-bowl:2 all:",
    "form around-bowl: all:", "form groups-by-class: all:",
    # language 2
    "every colours:orange+yellow in-bowl:any", "every all-but-colours:gray+brown on-table:",
    "every all: in-bowl-at:leftmost", "every colour:red in-bowl-at:front-most", "every all: in-bowl-at:central",
    "every all: side-of-bowls:behind", "none all: table-part:a-corner", "every all: table-part:an-edge",
    "form stacks:max-2 all:", "form stacks:pairs all:", "form tower-by-shade:dark-first all:",
    "form row-by-shade:dark-first@front-edge all:", "form by-each-bowl:front all:", "form by-each-bowl:next all:",
    "form two-bowls: class:warm", "every colour:green in-the-bowl-if-there:green",
    "every colour:red on-the-block-if-there:blue", "every all: next-to-if-there:gray block",
    "every colour:blue side-if-there:left/yellow block", "every all: in-bowl-else:left half",
    "every all: next-to-bowl-at:rightmost", "form bowl-load:max-2 all:", "form bowl-load:even all:",
    "form tower-by-name:alphabetical all:", "form row-by-name:alphabetical all:", "form even-halves: all:",
    # combinations
    "every class:warm in-bowl:any & every class:cool on-table:", "every class:warm in-bowl:any & stays",
    "every colour:red in-the-bowl:red & every colour:blue in-the-bowl:blue",
]

NOTES = """Notes: "front" is the side of the table near the person, "back" the far side. Rainbow order is
red, orange, yellow, green, blue, purple (colours outside it in any place). A block "in a bowl"
is in it; "on the table" means flat on the table (not in a bowl, not on a block). "matching:yes"
selects the blocks whose colour matches some bowl on the table. A second clause whose selector
is the same as the first's, or its complement (colour:X / all-but:X, class:warm / class:cool,
matching:yes / matching:no{}), is a reference to those blocks / the others."""

NOTES_2 = """ "Darkest" / "lightest" follow the lightness of the colours as the table shows
them, darkest first: purple, blue, brown, red, green, orange, cyan, gray, pink, yellow. A bowl
"at" a place is the one standing furthest that way (leftmost, nearest the front / back edge) or
nearest the middle of the table (central), whichever bowls are there that day. A relation
ending in "-if-there" makes its clause hold on a day the object it names is not on the table
(whatever the quantifier); without "-if-there", a clause about an absent object cannot hold."""

PLACES = """## Sizes and places (what each place accepts)

The table is 60 × 60 cm; blocks are 4 cm cubes; a bowl is 13 cm across. Split the table into a
3 × 3 grid of 20 cm squares: the *back strip* / *front strip* is the back / front row of the grid
(the third of the table farthest from / nearest the person); the *back half* / *front half* and
*left half* / *right half* are halves (30 cm); the *centre* is the grid's middle square; a *corner*
is a corner square of the grid. "Along an edge" (`@back-edge` …, `table-part:an-edge`) is
within 10 cm of that edge. Two objects are *next to* each other when their outlines are less
than 5 cm apart. `side:right/X` ("right of X") holds anywhere to the right of X's outline, at
any distance and any depth — for "right beside X" add `next-to:X`. A place clause (`region`,
`table-part`) holds only for a block standing on the table itself: a block in a bowl or on
another block is in no region; to place a tower or stack, use the structure's `@place`
parameter, which looks at the tower's bottom block. Rows and columns are of blocks standing on
the table in a straight line, each less than 5 cm from its neighbour (touching or nearly)."""


def known(key: str) -> str | None:
    """What is wrong with ``key`` in the language in force, or None."""
    from activeintent.goals.language import QUANTS, Form, nodes, parse_goal

    try:
        goal = parse_goal(key)
    except (ValueError, IndexError) as err:
        return f"cannot parse: {err}"
    for c in goal.clauses:
        for kind, name, param in (("selector", c.sel, c.sp),) + (
                (("structure", c.struct, c.stp),) if isinstance(c, Form) else (("relation", c.rel, c.rp),)):
            if name not in nodes(kind):
                return f"unknown {kind} {name!r}; valid: {', '.join(nodes(kind))}"
            if param not in nodes(kind)[name].params:
                if "+" in param and "+".join(reversed(param.split("+"))) in nodes(kind)[name].params:
                    return f"write the pair the other way round: {'+'.join(reversed(param.split('+')))}"
                return f"{kind} {name!r} has no parameter {param!r}"
        if not isinstance(c, Form) and c.quant not in QUANTS:
            return f"unknown quantifier {c.quant!r}; valid: {', '.join(QUANTS)}"
    if len(goal.clauses) > 3 or len({c.key for c in goal.clauses}) != len(goal.clauses):
        return "one to three different clauses"
    return None


def describe(places: bool = False) -> str:
    from activeintent.goals.language import QUANTS, nodes, parse_goal, spoken

    out = ["# The goal language (what a translator is given)", "",
           "A goal is one to three clauses joined by ' & ', optionally followed by ' & stays'",
           "(every block the clauses do not mention stays where it is). A goal holds in a final state when every "
           "clause holds.", "", "Clause forms (keys):",
           "- `QUANT SELECTOR:PARAM RELATION:PARAM` — e.g. `every colour:red on-the-block:blue`",
           "- `form STRUCTURE:PARAM SELECTOR:PARAM` — e.g. `form tower:any all:`  (structures take the selected "
           "blocks as a group)", "",
           f"Quantifiers: {', '.join(QUANTS)} (none = no selected block satisfies the relation).", ""]
    for kind in ("selector", "relation", "structure"):
        out += [f"## {kind}s (name: parameters)", ""]
        for key, node in nodes(kind).items():
            params = [p for p in node.params]
            text = (f"(no parameter: write `{key}:`)" if params == [""]
                    else ", ".join(f"`{p}`" for p in params))
            out.append(f"- `{key}`: {text}")
        out.append("")
    out += ["## What the names mean (each shown by one example clause and its sentence)", ""]
    for key in EXAMPLES:
        if known(key) is None:
            g = parse_goal(key)
            out.append(f"- `{key}` — {g.sentence()}  ({g.bits:.1f} bits)")
    pairs = ", colours:X+Y / all-but-colours:X+Y" if spoken() >= 2 else ""
    out += ["", NOTES.format(pairs) + (NOTES_2 if spoken() >= 2 else ""), ""]
    if places:
        out += [PLACES, ""]
    return "\n".join(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--language", type=int, default=None, help="language version (default: the latest)")
    ap.add_argument("--check", nargs="+", metavar="KEY", help="print each key's sentence and bits, or what is wrong")
    ap.add_argument("--places", action="store_true", help="add the sizes and extents of the places (pass 3 on)")
    args = ap.parse_args()
    from activeintent.goals.language import LATEST, parse_goal, speaking

    with speaking(args.language or LATEST):
        if not args.check:
            sys.stdout.write(describe(args.places))
            return
        for key in args.check:
            wrong = known(key)
            print(f"{key}\n  " + (f"NOT A GOAL: {wrong}" if wrong else
                                  f"{parse_goal(key).sentence()}  ({parse_goal(key).bits:.1f} bits)"))


if __name__ == "__main__":
    main()
