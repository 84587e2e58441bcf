"""The streamed reader (issue 23 item 1): a file read in many chunks gives the same arrays, the same
messages and the same row numbers as one read whole; its memory does not hold the file's text."""

import gzip

import numpy as np
import pytest

from heavecomp.errors import DataError
from heavecomp.io import series as S

COLS = ("t", "heave", "stroke", "pressure", "wob")


def _table(n=3000, seed=0):
    rng = np.random.default_rng(seed)
    t = 0.02 * np.arange(n)
    return np.column_stack([t, rng.normal(0, 1, n), rng.normal(0, 0.5, n), 1e7 + rng.normal(0, 1e5, n),
                            2e5 + rng.normal(0, 1e4, n)])


def _write(path, data, header="t,heave,stroke,pressure,wob", sep=",", lines=None):
    rows = [sep.join("%.10g" % v for v in r) for r in data]
    for k, text in (lines or {}).items():
        rows[k] = text
    text = header + "\n" + "\n".join(rows) + "\n"
    if str(path).endswith(".gz"):
        with gzip.open(path, "wt", encoding="utf-8") as fh:
            fh.write(text)
    else:
        path.write_bytes(text.encode("utf-8"))
    return path


@pytest.fixture
def small_chunks(monkeypatch):
    """Chunks of about 4 kB (a hundred rows): every file below is read in tens of chunks."""
    monkeypatch.setattr(S, "CHUNK_BYTES", 4096)
    monkeypatch.setattr(S, "FIRST_CHUNK_BYTES", 1024)


@pytest.mark.parametrize("name", ["log.csv", "log.csv.gz"])
def test_many_chunks_read_the_same_numbers_as_the_text(tmp_path, small_chunks, name):
    data = _table()
    s = S.read_series(_write(tmp_path / name, data), COLS)
    for j, c in enumerate(COLS):
        assert np.array_equal(s[c], np.array(["%.10g" % v for v in data[:, j]], dtype=float)), c
    assert np.array_equal(s.rows, np.arange(data.shape[0]) + 2)  # header on line 1


def test_iter_chunks_yields_consecutive_rows_in_bounded_pieces(tmp_path, small_chunks):
    data = _table()
    parts = list(S.iter_chunks(_write(tmp_path / "log.csv", data), COLS))
    assert len(parts) > 10
    assert max(p.rows.size for p in parts) < data.shape[0] / 10
    assert np.array_equal(np.concatenate([p.rows for p in parts]), np.arange(data.shape[0]) + 2)
    assert np.array_equal(np.concatenate([p["wob"] for p in parts]), np.array(["%.10g" % v for v in data[:, 4]],
                                                                               dtype=float))


@pytest.mark.parametrize("bad, fragment", [
    ("1,2,3,4,5,6", "row 2702 has 6 fields, the header has 5 (',' separated; a stray delimiter"),
    ("1,2,3,4", "row 2702 has 4 fields, the header has 5"),
    ("54.0,0.1,abc,1e7,2e5", "column 'stroke', row 2702: not a number: 'abc'"),
])
def test_a_problem_deep_in_the_file_is_named_by_its_line(tmp_path, small_chunks, bad, fragment):
    f = _write(tmp_path / "log.csv.gz", _table(), lines={2700: bad})
    with pytest.raises(DataError) as e:
        S.read_series(f, COLS)
    assert fragment in str(e.value) and "\n" not in str(e.value)


def test_comments_and_blank_lines_keep_the_line_numbers(tmp_path, small_chunks):
    data = _table()
    f = _write(tmp_path / "log.csv", data, lines={1000: "# operator note", 2000: ""})
    s = S.read_series(f, COLS)
    assert s["t"].size == data.shape[0] - 2
    k = int(np.flatnonzero(s.rows == 2004)[0])  # data row 2002 on line 2004, after a comment and a blank line
    assert s["t"][k] == float("%.10g" % data[2002, 0]) and 1002 not in s.rows and 2002 not in s.rows


def test_latin1_after_the_first_chunk_is_read_again_as_latin1(tmp_path, small_chunks):
    data = _table(600)
    rows = ["%.10g,%.10g,%.10g,%.10g,%.10g" % tuple(r) for r in data]
    text = ("t,heave,stroke,pressure,wob,note\n" + "\n".join(r + ",x" for r in rows[:500]) + "\n"
            + "\n".join(r + ",\xb0C" for r in rows[500:]) + "\n")
    f = tmp_path / "log.csv"
    f.write_bytes(text.encode("latin-1"))
    s = S.read_series(f, COLS)
    assert s["t"].size == 600 and any("read as Latin-1" in w for w in s.warnings)


def test_a_text_column_carried_along_is_dropped_whole(tmp_path, small_chunks):
    data = _table()
    rows = ["%.10g,%.10g,%.10g,%.10g,%.10g" % tuple(r) for r in data]
    extra = ["%d" % k if k < 2500 else "late text" for k in range(len(rows))]
    f = tmp_path / "log.csv"
    f.write_text("t,heave,stroke,pressure,wob,counter\n" + "\n".join(r + "," + x for r, x in zip(rows, extra)) + "\n")
    s = S.read_series(f, COLS)
    assert "counter" not in s.columns and s["wob"].size == data.shape[0]


def test_iso_timestamps_over_chunks_count_from_the_first_sample(tmp_path, small_chunks):
    n = 800
    ts = np.datetime64("2026-11-26T00:00:00") + (np.arange(n) * 100).astype("timedelta64[ms]")
    data = _table(n)
    f = tmp_path / "log.csv"
    f.write_text("time,heave,stroke,pressure,wob\n" + "\n".join(
        f"{str(a)}Z,%.10g,%.10g,%.10g,%.10g" % tuple(r[1:]) for a, r in zip(ts, data)) + "\n")
    s = S.read_series(f, COLS)
    assert np.allclose(s["t"], 0.1 * np.arange(n), atol=1e-9)
    assert s.measurement["units"]["t"] == "timestamp"


def test_parquet_is_read_by_row_groups(tmp_path, monkeypatch):
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    monkeypatch.setattr(S, "PARQUET_ROWS", 500)
    data = _table()
    f = tmp_path / "log.parquet"
    pq.write_table(pa.table({c: data[:, j] for j, c in enumerate(COLS)}), f, row_group_size=700)
    parts = list(S.iter_chunks(f, COLS))
    assert len(parts) >= 6
    s = S.read_series(f, COLS)
    assert np.array_equal(s["pressure"], data[:, 3]) and np.array_equal(s.rows, np.arange(data.shape[0]) + 1)


def test_too_many_samples_are_refused_by_name(tmp_path, small_chunks, monkeypatch):
    monkeypatch.setattr(S, "MAX_ARRAY_BYTES", 50_000)
    with pytest.raises(DataError) as e:
        S.read_series(_write(tmp_path / "log.csv", _table()), COLS)
    msg = str(e.value)
    assert "MB of samples by row" in msg and "cut the log into parts" in msg and "\n" not in msg


def test_the_rows_are_estimated_from_the_size_before_reading(tmp_path):
    import bz2

    data = _table(5000)
    plain = _write(tmp_path / "log.csv", data)
    gz = _write(tmp_path / "log.csv.gz", data)
    for f in (plain, gz):
        assert abs(S.estimate_rows(f) - 5000) < 250, f
    (tmp_path / "log.csv.bz2").write_bytes(bz2.compress(plain.read_bytes()))
    assert S.estimate_rows(tmp_path / "log.csv.bz2") is None  # bzip2 does not record its size
    assert S.estimate_rows(tmp_path / "missing.csv") is None  # the reader names what is wrong
    pa = pytest.importorskip("pyarrow")
    import pyarrow.parquet as pq

    pq.write_table(pa.table({c: data[:, j] for j, c in enumerate(COLS)}), tmp_path / "log.parquet")
    assert S.estimate_rows(tmp_path / "log.parquet") == 5000


@pytest.mark.parametrize("name", ["log.csv", "log.parquet"])
def test_chunks_show_callers_no_private_key(tmp_path, small_chunks, name):
    """The reader's own bookkeeping (whether the time unit was declared) stays out of ``measurement``, which a
    caller records in its results: every chunk's and the joined series' keys are the documented ones."""
    data = _table()
    if name.endswith(".parquet"):
        pa = pytest.importorskip("pyarrow")
        import pyarrow.parquet as pq

        f = tmp_path / name
        pq.write_table(pa.table({c: data[:, j] for j, c in enumerate(COLS)}), f)
    else:
        f = _write(tmp_path / name, data)
    parts = list(S.iter_chunks(f, COLS))
    for m in [p.measurement for p in parts] + [S.read_series(f, COLS).measurement]:
        assert not [k for k in m if k.startswith("_")], sorted(m)
        assert {"format", "columns", "units", "conversions"} <= set(m)
