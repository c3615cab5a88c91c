"""Table: rows with named columns, as the bench's CSV files hold them (results.csv, precision.csv, ...)."""
import csv

import numpy as np


def _value(text):
    """A CSV field as the number it spells (int, float, nan, inf) or the text itself."""
    try:
        return int(text)
    except ValueError:
        pass
    try:
        return float(text)
    except ValueError:
        return text


class Table:
    """Rows (tuples) under column names. table["col"] is that column as a NumPy array; iterating gives one dict per
    row; to_pandas() a DataFrame (pandas is not a dependency); to_records() a NumPy record array."""

    def __init__(self, columns, rows, **extra):
        self.columns = list(columns)
        self.rows = [tuple(r) for r in rows]
        for key, value in extra.items():
            setattr(self, key, value)

    @classmethod
    def read_csv(cls, path, **extra):
        """A CSV file with a header line; fields that spell numbers become numbers."""
        with open(path, newline="", encoding="utf-8") as f:
            reader = csv.reader(f)
            columns = next(reader)
            rows = [[_value(v) for v in row] for row in reader]
        # an empty field of a numeric column (a metric that does not apply) is NaN
        for i in range(len(columns)):
            values = [r[i] for r in rows if r[i] != ""]
            if values and all(isinstance(v, (int, float)) for v in values):
                for r in rows:
                    if r[i] == "":
                        r[i] = float("nan")
        return cls(columns, rows, **extra)

    def __len__(self):
        return len(self.rows)

    def __iter__(self):
        for row in self.rows:
            yield dict(zip(self.columns, row))

    def __getitem__(self, key):
        if isinstance(key, str):
            i = self.columns.index(key)
            values = [row[i] for row in self.rows]
            if all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in values):
                return np.array(values, dtype=np.float64 if any(isinstance(v, float) for v in values) else np.int64)
            return np.array(values, dtype=object)
        return dict(zip(self.columns, self.rows[key]))

    def where(self, **equal):
        """The rows whose columns equal the given values, as a Table."""
        index = [self.columns.index(k) for k in equal]
        wanted = list(equal.values())
        return Table(self.columns, [r for r in self.rows if [r[i] for i in index] == wanted])

    def to_records(self):
        return np.rec.fromrecords(self.rows, names=self.columns) if self.rows else None

    def to_pandas(self):
        import pandas as pd
        return pd.DataFrame(self.rows, columns=self.columns)

    def __repr__(self):
        return f"<polydyn.Table {len(self.rows)} rows × {len(self.columns)} columns: {', '.join(self.columns[:8])}...>"
