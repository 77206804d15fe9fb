"""A simulator's messages counted as distinct messages, its numbers standing as #."""

from cphysfno_core.data.messages import full_log, message_of, summary, tally


def test_numbers_stand_as_hash_but_names_and_powers_stay():
    line = "WARNING: CTestNormDispIncr::test() - failed after: 10 iterations  Norm: 1.2e-05"
    assert (
        message_of(line)
        == "WARNING: CTestNormDispIncr::test() - failed after: # iterations Norm: #"
    )
    assert message_of("  Steel01 at t=-0.30 in m/s^2 ") == "Steel01 at t=# in m/s^2"


def test_tally_counts_lines_and_summary_counts_records_too():
    texts = {3: "a at 1\na at 2\n\nb\n", 7: "a at 5\n"}
    assert tally(texts.values()) == {"a at #": 3, "b": 1}
    shown = summary(texts, limit=1)
    assert shown.splitlines() == [
        "the simulator printed 2 distinct messages (numbers written #):",
        "        3 times in     2 records: a at #",
        "  ... and 1 more distinct messages",
    ]
    assert summary({}) == ""
    assert full_log(texts) == "record 3:\na at 1\na at 2\n\nb\n\nrecord 7:\na at 5\n"
