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




def test_a_second_order_bodys_incumbent_asks_for_the_mean_pace():
    """Where M_phi sees each step's change and the user set no clip, the incumbent clips the query to the mean
    training step (1) and the query as asked is its rival; a clip the user set stands; elsewhere none, then 2."""
    from shaped_es.guides.probe_variants import STEP_CHANGE_CLIP, clips, long_variants

    assert clips(None, True) == [STEP_CHANGE_CLIP, None] and STEP_CHANGE_CLIP == 1.0
    assert clips(None) == [None, 2.0] and clips(3.0, True) == clips(3.0) == [3.0]
    assert variants(None, 0, step_change=True) == [("both", 1.0, None), ("both", None, None), ("world", 1.0, None),
                                                   ("world", None, None)]
    assert [variant_name(*v) for v in variants(None, 4, ("world",), True)] == [
        "world+clip1", "world", "world+chunk4+clip1", "world+chunk4"]
    assert long_variants(None, 4.0) == [("both", 4.0, None), ("world", 4.0, None)]  # the longer clip either way
