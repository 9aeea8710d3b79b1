"""Time and frequency: electrode charge and capacitance, the charging transient (reduced
circuit, PNP solver) and the small-signal response."""
