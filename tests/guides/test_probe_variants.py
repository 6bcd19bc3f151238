"""What the label probe tries (guides/probe_variants.py): the variants, in order, and their names."""

from shaped_es.guides.probe_variants import variant_name, variant_text, variants


def test_variants_keep_a_clip_the_user_set():
    assert variants(None) == [("both", None, None), ("both", 2.0, None), ("world", None, None), ("world", 2.0, None)]
    assert variants(3.0) == [("both", 3.0, None), ("world", 3.0, None)]


def test_chunk_variants_follow_the_one_step_ones_and_name_their_settings():
    vs = variants(None, 4)
    assert vs[:4] == variants(None) and vs[4:] == [(f, c, 4) for f in ("both", "world") for c in (None, 2.0)]
    assert [variant_name(*v) for v in vs[4:]] == ["both+chunk4", "both+chunk4+clip2", "world+chunk4",
                                                  "world+chunk4+clip2"]
    assert variant_text("both+chunk4+clip2") == "frame=both, targets=chunk (4 steps), query_clip=2"
    assert variant_text("world") == "frame=world, query_clip=none"
