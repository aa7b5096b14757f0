"""Case files: one schema per kind (impact, towing, diagnosis, approach), the input
limits every kind shares, the kind table and the schema documentation."""
