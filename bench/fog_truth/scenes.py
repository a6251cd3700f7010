"""The fog truth's scenes, described once in veil's coordinates (y up, metres).

Read by truth.py (inside Blender, which is z up: blender (X, Y, Z) = veil
(x, -z, y)) and by make_veil_scenes.py (the veil scene JSON). Units are
veil's (docs/scene-format.md): sigma_a and sigma_s in m^-1 per unit density,
point intensity in W/sr, directional irradiance in W/m^2.

Two cases, each rendered without fog (the frame `veil fog` reads) and with:
- night: a street between two walls, three point lamps, thick homogeneous fog;
- day: the same street under a sun, exponential height fog.
"""

WIDTH, HEIGHT = 160, 120

CAMERA = {"position": [0.0, 1.7, 6.0], "look_at": [0.0, 2.2, -20.0], "up": [0.0, 1.0, 0.0],
          "fov_y_deg": 50.0, "width": WIDTH, "height": HEIGHT}

# Axis-aligned boxes [min, max] with a diffuse albedo: the "street".
BOXES = [
    ([-40.0, -1.0, -100.0], [40.0, 0.0, 40.0], [0.30, 0.30, 0.30]),   # ground, top face at y = 0
    ([-5.5, 0.0, -70.0], [-4.5, 9.0, 12.0], [0.55, 0.45, 0.35]),       # left facade
    ([4.5, 0.0, -70.0], [5.5, 7.0, 12.0], [0.45, 0.50, 0.55]),         # right facade
    ([-5.5, 0.0, -71.0], [5.5, 12.0, -70.0], [0.50, 0.50, 0.50]),      # the street's far end
    ([-3.2, 0.0, -9.0], [-1.4, 1.4, -4.5], [0.60, 0.20, 0.15]),        # cars
    ([1.4, 0.0, -19.0], [3.2, 1.5, -14.5], [0.15, 0.30, 0.60]),
    ([-3.2, 0.0, -31.0], [-1.5, 1.3, -26.5], [0.70, 0.70, 0.65]),
]

FOG_BOX = [[-40.0, -1.0, -100.0], [40.0, 40.0, 40.0]]

CASES = {
    "night": {
        "lights": [
            {"type": "point", "position": [-3.6, 5.0, -6.0], "intensity": [60.0, 48.0, 30.0]},
            {"type": "point", "position": [3.6, 5.0, -17.0], "intensity": [60.0, 48.0, 30.0]},
            {"type": "point", "position": [-3.6, 5.0, -30.0], "intensity": [60.0, 48.0, 30.0]},
        ],
        "sigma_s": [0.10, 0.10, 0.10], "sigma_a": [0.01, 0.01, 0.01], "g": 0.5,
        "fog": {"density": 1.0, "falloff": 0.0},
    },
    "day": {
        "lights": [
            {"type": "directional", "direction": [0.45, -0.75, -0.50], "irradiance": [3.0, 2.9, 2.7]},
        ],
        "sigma_s": [0.06, 0.06, 0.06], "sigma_a": [0.006, 0.006, 0.006], "g": 0.6,
        "fog": {"density": 1.0, "falloff": 0.2},
    },
}


def veil_scene(case, lights=True, multiple=None):
    """The veil scene JSON (a dict) of a case; lights=False drops them."""
    c = CASES[case]
    scene = {
        "camera": dict(CAMERA),
        "medium": {
            "sigma_a": c["sigma_a"], "sigma_s": c["sigma_s"],
            "phase": {"type": "hg", "g": c["g"]},
            "sources": [{"type": "exponential", "density": c["fog"]["density"], "falloff": c["fog"]["falloff"],
                         "direction": [0.0, 1.0, 0.0], "origin": [0.0, 0.0, 0.0], "bounds": FOG_BOX}],
        },
        "lights": c["lights"] if lights else [],
        "background": {"color": [0.0, 0.0, 0.0]},
    }
    if multiple:
        scene["multiple_scattering"] = multiple
    return scene
