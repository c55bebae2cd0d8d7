"""The selectors of the goal language: which blocks a clause is about (all, one colour, a
colour class, those whose colour matches a bowl, all but one colour)."""

from __future__ import annotations

from activeintent.goals.nodes import Selector, register
from activeintent.world.colors import COLOR_NAMES, COOL_COLORS, WARM_COLORS
from activeintent.world.scene import color_of, own_bowl


class AllBlocks(Selector):
    key = "all"

    def noun(self, p):
        return "block"

    def pick(self, block, bowls, p):
        return True


class ColourBlock(Selector):
    key = "colour"
    params = COLOR_NAMES

    def noun(self, p):
        return f"{p} block"

    def pick(self, block, bowls, p):
        return color_of(block) == p


class ColourClass(Selector):
    key = "class"
    params = ("warm", "cool")

    def noun(self, p):
        return f"{p}-coloured block"

    def pick(self, block, bowls, p):
        return color_of(block) in (WARM_COLORS if p == "warm" else COOL_COLORS)


class BowlMatch(Selector):
    key = "matching"
    params = ("yes", "no")

    def noun(self, p):
        return "block whose colour matches a bowl" if p == "yes" else "block whose colour matches no bowl"

    def pick(self, block, bowls, p):
        return (own_bowl(block) in bowls) == (p == "yes")


class AllBut(Selector):
    """Every block except the one(s) of one colour ("all the blocks but the green one")."""

    key = "all-but"
    params = COLOR_NAMES

    def noun(self, p):
        return f"block other than the {p} one"

    def pick(self, block, bowls, p):
        return color_of(block) != p



for _node in (AllBlocks(), ColourBlock(), ColourClass(), BowlMatch(), AllBut()):
    register(_node)
