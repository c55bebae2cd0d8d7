"""The ten colours of blocks and bowls (RGB in [0, 1]): the Code-as-Policies palette, except purple,
whose mauve (176, 122, 161) read as pink in the videos (tests/sim/test_camera.py checks each colour
against its name)."""

COLORS: dict[str, tuple[float, float, float]] = {
    "blue": (78 / 255, 121 / 255, 167 / 255),
    "red": (255 / 255, 87 / 255, 89 / 255),
    "green": (89 / 255, 169 / 255, 79 / 255),
    "orange": (242 / 255, 142 / 255, 43 / 255),
    "yellow": (237 / 255, 201 / 255, 72 / 255),
    "purple": (130 / 255, 95 / 255, 180 / 255),
    "pink": (255 / 255, 157 / 255, 167 / 255),
    "cyan": (118 / 255, 183 / 255, 178 / 255),
    "brown": (156 / 255, 117 / 255, 95 / 255),
    "gray": (186 / 255, 176 / 255, 172 / 255),
}
COLOR_NAMES: tuple[str, ...] = tuple(COLORS)

# Colour properties used by intentions such as "warm colours in bowls, cool colours stacked".
WARM_COLORS = frozenset({"red", "orange", "yellow", "pink", "brown"})
COOL_COLORS = frozenset({"blue", "green", "purple", "cyan", "gray"})
