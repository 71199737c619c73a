#!/usr/bin/env python3
"""Regenerate the bad web-file corpus from tests/data/io/chain4.json.

Each file breaks the good file in exactly one way. The expected message for
each lives in tests/test_io_web.c (the table `corpus`); add a file here and a
row there together. Run from anywhere: python3 tests/data/bad/generate.py
"""
import json, os, copy

here = os.path.dirname(os.path.abspath(__file__))
good_text = open(os.path.join(here, "..", "io", "chain4.json")).read()
good = json.loads(good_text)


def write(name, text):
    with open(os.path.join(here, name), "w") as f:
        f.write(text)


def variant(name, edit):
    doc = copy.deepcopy(good)
    edit(doc)
    write(name, json.dumps(doc, indent=1) + "\n")


def sub(old, new):
    assert good_text.count(old) == 1, old
    return good_text.replace(old, new)


write("empty.json", "")
write("blank.json", "  \n\t\n")
write("truncated.json", good_text[: len(good_text) // 2])
write("nan_literal.json", sub('"drag": 2', '"drag": NaN'))
write("duplicate_field.json", sub('"mass": [0, 0.001, 0.001, 0],', '"mass": [0, 0.001, 0.001, 0],\n    "mass": [1, 1, 1, 1],'))
write("trailing_text.json", good_text + "{}\n")
write("top_array.json", "[1, 2, 3]\n")
with open(os.path.join(here, "nul_byte.json"), "wb") as f:
    f.write(good_text.encode()[:40] + b"\0" + good_text.encode()[40:])
variant("missing_format.json", lambda d: d.pop("format"))
variant("unknown_format.json", lambda d: d.update(format="obj-mesh"))
variant("version_2.json", lambda d: d.update(version=2))
variant("version_string.json", lambda d: d.update(version="1"))
variant("units_imperial.json", lambda d: d.update(units="imperial"))
variant("metadata_array.json", lambda d: d.update(metadata=[1, 2]))
variant("missing_particles.json", lambda d: d.pop("particles"))
variant("missing_mass.json", lambda d: d["particles"].pop("mass"))
variant("missing_rest.json", lambda d: d["springs"].pop("rest"))
variant("missing_count.json", lambda d: d["springs"].pop("count"))
variant("position_short.json", lambda d: d["particles"]["position"].pop())
variant("k_short.json", lambda d: d["springs"]["k"].pop())
variant("tag_long.json", lambda d: d["particles"]["tag"].append(0))
write("position_inf.json", sub("-0.035, 0, 0", "-0.035, 1e999, 0"))
variant("mass_negative.json", lambda d: d["particles"]["mass"].__setitem__(2, -0.001))
variant("mass_string.json", lambda d: d["particles"]["mass"].__setitem__(1, "heavy"))
variant("fixed_two.json", lambda d: d["particles"]["fixed"].__setitem__(3, 2))
variant("spring_to_missing.json", lambda d: d["springs"]["b"].__setitem__(1, 7))
variant("spring_to_itself.json", lambda d: d["springs"]["b"].__setitem__(2, 2))
variant("spring_negative_end.json", lambda d: d["springs"]["a"].__setitem__(0, -1))
variant("k_negative.json", lambda d: d["springs"]["k"].__setitem__(1, -20))
variant("tag_fraction.json", lambda d: d["springs"]["tag"].__setitem__(2, 1.5))
variant("break_max_below_min.json", lambda d: (d["springs"]["break_min"].__setitem__(0, 0.02),
                                               d["springs"]["break_max"].__setitem__(0, 0.01)))
variant("count_too_big.json", lambda d: d["particles"].update(count=4000000000))
variant("count_huge_short.json", lambda d: d["particles"].update(count=90000000))
variant("unknown_field.json", lambda d: d["particles"].update(colour=[0, 0, 0, 0]))
variant("integrator_unknown.json", lambda d: d["world"].update(integrator="verlet"))
variant("gravity_short.json", lambda d: d["world"].update(gravity=[0, -9.81]))
variant("drag_negative.json", lambda d: d["world"].update(drag=-1))
variant("particles_array.json", lambda d: d.update(particles=[1, 2, 3]))
