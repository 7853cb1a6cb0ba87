#!/usr/bin/env python3
"""trace.parquet read by Arrow and pandas, checked against trace.csv: the same columns
in the same order, the same number of rows, and every value equal (floats bit for bit,
NaN to NaN); the unsigned columns unsigned. With --dataset DIR --runs N --rows R, a
sweep's traces/ folder read as one table by pandas.read_parquet, with its combination
columns.

Usage: parquet_check.py TRACE.csv TRACE.parquet
       parquet_check.py --dataset DIR --runs N --rows R --keys K1,K2
"""
import sys

import numpy as np
import pandas as pd
import pyarrow.parquet as pq


def fail(msg):
    print(f"FAIL: {msg}")
    sys.exit(1)


def check_trace(csv_path, parquet_path):
    table = pq.read_table(parquet_path)
    # Read as text, each float parsed by Python's float (correctly rounded, so the
    # shortest round-trip text gives back the very double the CSV was written from).
    csv = pd.read_csv(csv_path, dtype=str, keep_default_na=False)
    par = table.to_pandas()
    if list(csv.columns) != list(par.columns):
        fail(f"columns differ: {list(csv.columns)[:5]}... vs {list(par.columns)[:5]}...")
    if len(csv) != len(par):
        fail(f"{len(csv)} CSV rows, {len(par)} Parquet rows")
    meta = pq.ParquetFile(parquet_path).metadata
    codecs = {meta.row_group(0).column(k).compression for k in range(meta.num_columns)}
    if codecs != {"ZSTD"}:
        fail(f"compression {codecs}, not ZSTD")
    kinds = {}
    for name in csv.columns:
        b = par[name].to_numpy()
        text = csv[name].to_numpy()
        if b.dtype == np.float64:
            a = np.array([float(x) for x in text], dtype=np.float64)
        else:
            a = np.array([int(x) for x in text], dtype=np.uint64 if b.dtype.kind == "u" else np.int64)
        kinds[b.dtype.name] = kinds.get(b.dtype.name, 0) + 1
        if b.dtype == np.float64:
            same = (a == b) | (np.isnan(a) & np.isnan(b))
            # Bit for bit too: -0.0 and 0.0 compare equal above.
            same &= np.signbit(a) == np.signbit(b)
        else:
            same = a == b.astype(a.dtype)
        if not same.all():
            k = int(np.argmin(same))
            fail(f"{name}, row {k}: CSV {a[k]!r}, Parquet {b[k]!r}")
    for name in ["n", "delay_f_1", "q_from_1", "t_master_tick"]:
        if par[name].dtype.kind != "u":
            fail(f"{name} is {par[name].dtype}, not unsigned")
    print(
        f"trace.parquet equals trace.csv: {len(csv)} rows, {len(csv.columns)} columns "
        f"({', '.join(f'{v} {k}' for k, v in sorted(kinds.items()))}), zstd"
    )


def check_dataset(folder, runs, rows, keys):
    df = pd.read_parquet(folder)
    if len(df) != runs * rows:
        fail(f"{len(df)} rows, want {runs} runs of {rows}")
    for key in keys + ["run"]:
        if key not in df.columns:
            fail(f"no column {key!r}")
    if df["run"].nunique() != runs:
        fail(f"{df['run'].nunique()} runs in the dataset, want {runs}")
    # Each run one combination, each combination its own run.
    combos = df.groupby("run")[keys].nunique()
    if (combos != 1).any().any():
        fail(f"a run with more than one value of a key: {combos.to_dict()}")
    if len(df.drop_duplicates(keys + ["run"])) != runs or len(df.drop_duplicates(keys)) != runs:
        fail("two runs share a combination")
    per = df.groupby(keys)["n"].count()
    if (per != rows * runs // len(per)).any():
        fail(f"rows per combination: {per.to_dict()}")
    print(f"the sweep's traces read as one table: {len(df)} rows, {df['run'].nunique()} runs, "
          f"{len(per)} combinations of {', '.join(keys)}")


if __name__ == "__main__":
    args = sys.argv[1:]
    if args and args[0] == "--dataset":
        opts = dict(zip(args[0::2], args[1::2]))
        check_dataset(opts["--dataset"], int(opts["--runs"]), int(opts["--rows"]), opts["--keys"].split(","))
    elif len(args) == 2:
        check_trace(args[0], args[1])
    else:
        fail(__doc__)
