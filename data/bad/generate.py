#!/usr/bin/env python3
"""Writes the generated members of the bad-input catalogue (see CATALOGUE.tsv) into this folder.

Hand-written cases are checked in as they are; this script only makes the ones that are tedious to
write by hand (binary STL, STEP assemblies built on ../cad/valid_two_solids.step). Re-run it after
changing a case: `python3 data/bad/generate.py`.
"""
import os
import struct

HERE = os.path.dirname(os.path.abspath(__file__))
BASE_STEP = os.path.join(HERE, "..", "cad", "valid_two_solids.step")


def write(name, data):
    mode = "wb" if isinstance(data, bytes) else "w"
    with open(os.path.join(HERE, name), mode) as f:
        f.write(data)


def tri(n, a, b, c):
    return struct.pack("<12fH", *n, *a, *b, *c, 0)


def binary_stl():
    header = b"cadclash bad-input catalogue".ljust(80, b" ")
    one = tri((0, 0, 1), (0, 0, 0), (1, 0, 0), (0, 1, 0))
    # Announces a million triangles, holds one.
    write("stl_binary_count_too_large.stl", header + struct.pack("<I", 1000000) + one)
    # Announces two triangles, the second cut after 20 bytes.
    write("stl_binary_truncated.stl", header + struct.pack("<I", 2) + one + one[:20])
    # Header cut short: 40 bytes, no count.
    write("stl_binary_short_header.stl", b"\0" * 40)
    # A NaN vertex in the first of two triangles.
    nan = float("nan")
    write("stl_binary_nan.stl", header + struct.pack("<I", 2) +
          tri((0, 0, 1), (nan, 0, 0), (1, 0, 0), (0, 1, 0)) +
          tri((0, 0, 1), (0, 0, 0), (1, 0, 0), (0, 1, 0)))
    # A good facet, then a zero-area (collinear) one: kept, with a warning naming facet 1 at byte 134.
    write("stl_binary_zero_area.stl", header + struct.pack("<I", 2) +
          tri((0, 0, 1), (0, 0, 0), (1, 0, 0), (0, 1, 0)) +
          tri((0, 0, 1), (0, 0, 0), (1, 0, 0), (2, 0, 0)))
    # A header that begins with "solid" like an ASCII file, with the size of a binary one.
    solid_header = b"solid binary STL whose header starts like ASCII".ljust(80, b" ")
    write("stl_binary_solid_header.stl", solid_header + struct.pack("<I", 1) + one)


def step_parts():
    """valid_two_solids.step split into (head up to the last entity, tail 'ENDSEC;...')."""
    text = open(BASE_STEP).read()
    cut = text.rindex("ENDSEC;")
    return text[:cut], text[cut:]


def product(first_id, name):
    """Entities of an assembly product whose shape is an empty SHAPE_REPRESENTATION with one axis.
    Returns (text, product_definition_id, shape_representation_id, axis_id)."""
    i = first_id
    text = (
        f"#{i} = PRODUCT('{name}','{name}','',(#8));\n"
        f"#{i+1} = PRODUCT_DEFINITION_FORMATION('','',#{i});\n"
        f"#{i+2} = PRODUCT_DEFINITION('design','',#{i+1},#9);\n"
        f"#{i+3} = PRODUCT_DEFINITION_SHAPE('','',#{i+2});\n"
        f"#{i+4} = SHAPE_REPRESENTATION('',(#{i+5}),#345);\n"
        f"#{i+5} = AXIS2_PLACEMENT_3D('',#12,#13,#14);\n"
        f"#{i+6} = SHAPE_DEFINITION_REPRESENTATION(#{i+3},#{i+4});\n")
    return text, i + 2, i + 4, i + 5


def usage(first_id, parent_pd, parent_rep, parent_axis, child_pd, child_rep, child_axis):
    i = first_id
    return (
        f"#{i} = NEXT_ASSEMBLY_USAGE_OCCURRENCE('{i}','','',#{parent_pd},#{child_pd},$);\n"
        f"#{i+1} = PRODUCT_DEFINITION_SHAPE('','',#{i});\n"
        f"#{i+2} = ITEM_DEFINED_TRANSFORMATION('','',#{child_axis},#{parent_axis});\n"
        f"#{i+3} = ( REPRESENTATION_RELATIONSHIP('','',#{child_rep},#{parent_rep}) "
        f"REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION(#{i+2}) SHAPE_REPRESENTATION_RELATIONSHIP() );\n"
        f"#{i+4} = CONTEXT_DEPENDENT_SHAPE_REPRESENTATION(#{i+3},#{i+1});\n")


def step_cycle():
    # Assembly A holds B, B holds A and the solid of #5: A is its own ancestor.
    head, tail = step_parts()
    a, a_pd, a_rep, a_ax = product(10000, "A")
    b, b_pd, b_rep, b_ax = product(10010, "B")
    body = a + b
    body += usage(10100, a_pd, a_rep, a_ax, b_pd, b_rep, b_ax)
    body += usage(10110, b_pd, b_rep, b_ax, a_pd, a_rep, a_ax)
    body += usage(10120, b_pd, b_rep, b_ax, 5, 10, 11)
    write("step_cyclic_assembly.step", head + body + tail)
    # The smallest cycle: a product that holds itself.
    s, s_pd, s_rep, s_ax = product(10000, "SELF")
    body = s + usage(10100, s_pd, s_rep, s_ax, s_pd, s_rep, s_ax) + usage(10110, s_pd, s_rep, s_ax, 5, 10, 11)
    write("step_self_assembly.step", head + body + tail)


def step_deep(levels=300):
    # A chain of `levels` assemblies, each holding the next; the last holds the solid of #5.
    head, tail = step_parts()
    body, prev = [], None
    for k in range(levels):
        text, pd, rep, ax = product(10000 + 20 * k, f"L{k}")
        body.append(text)
        if prev:
            body.append(usage(10000 + 20 * k + 10, *prev, pd, rep, ax))
        prev = (pd, rep, ax)
    body.append(usage(10000 + 20 * levels + 10, *prev, 5, 10, 11))
    write("step_deep_assembly.step", head + "".join(body) + tail)


def step_no_units():
    # Both 3D contexts lose their GLOBAL_UNIT_ASSIGNED_CONTEXT and the unit entities are gone.
    text = open(BASE_STEP).read()
    import re
    text = re.sub(r"GLOBAL_UNIT_ASSIGNED_CONTEXT\s*\(\([^)]*\)\)", "", text)
    text = re.sub(r"GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT\(\(#\d+\)\)", "", text)
    text = re.sub(r"#\d+ = \( *(LENGTH_UNIT|NAMED_UNIT)[^;]*;\n", "", text)
    text = re.sub(r"#\d+ = UNCERTAINTY_MEASURE_WITH_UNIT\([^;]*;\n", "", text)
    write("step_no_units.step", text)


def step_no_length_unit():
    # The 3D context's unit list keeps the angle units but loses the length unit: OCCT says nothing.
    text = open(BASE_STEP).read()
    text = text.replace("GLOBAL_UNIT_ASSIGNED_CONTEXT\n((#346,#347,#348))", "GLOBAL_UNIT_ASSIGNED_CONTEXT\n((#347,#348))")
    write("step_no_length_unit.step", text)


def step_deep_entity_chain(length=5000):
    # The first part's shape reached through a chain of `length` MAPPED_ITEMs, each mapping a
    # representation that holds the next one; the last holds the solid #15.
    head, tail = step_parts()
    head = head.replace("#3 = SHAPE_DEFINITION_REPRESENTATION(#4,#10);", "#3 = SHAPE_DEFINITION_REPRESENTATION(#4,#20000);")
    body = []
    i = 20000
    body.append(f"#{i} = SHAPE_REPRESENTATION('chain',(#{i+1}),#345);\n")
    for k in range(length):
        j = i + 1 + 3 * k
        body.append(f"#{j} = MAPPED_ITEM('',#{j+1},#11);\n")
        body.append(f"#{j+1} = REPRESENTATION_MAP(#11,#{j+2});\n")
        nxt = f"#{j+3}" if k + 1 < length else "#15"
        body.append(f"#{j+2} = SHAPE_REPRESENTATION('',(#11,{nxt}),#345);\n")
    write("step_deep_entity_chain.step", head + "".join(body) + tail)


def step_mapped_cycle():
    # The first part's shape is a MAPPED_ITEM whose representation holds that same MAPPED_ITEM.
    head, tail = step_parts()
    head = head.replace("#3 = SHAPE_DEFINITION_REPRESENTATION(#4,#10);", "#3 = SHAPE_DEFINITION_REPRESENTATION(#4,#20000);")
    body = ("#20000 = SHAPE_REPRESENTATION('loop',(#11,#20001),#345);\n"
            "#20001 = MAPPED_ITEM('',#20002,#11);\n"
            "#20002 = REPRESENTATION_MAP(#11,#20000);\n")
    write("step_mapped_item_cycle.step", head + body + tail)


def garbage():
    # Deterministic binary noise under each text format's extension.
    import random
    rng = random.Random(7)
    for name in ("off_garbage.off", "step_garbage.step", "iges_garbage.igs", "brep_garbage.brep"):
        write(name, bytes(rng.randrange(256) for _ in range(512)))


if __name__ == "__main__":
    garbage()
    binary_stl()
    step_cycle()
    step_deep()
    step_no_units()
    step_no_length_unit()
    step_deep_entity_chain()
    step_mapped_cycle()
