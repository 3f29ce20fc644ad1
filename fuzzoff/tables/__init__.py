"""What the PX4 docs state, as data looked up by profile: one module per subject.

These are the docs' tables (the rules follow the docs). What PX4's code does lives with the gate
model in ``fuzzoff/gate/``; where the two differ, the rule's page says so.
"""
