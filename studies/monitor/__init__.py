"""The `monitor` study: false alarms and detection delays, with an oracle and a fixed-threshold baseline."""
