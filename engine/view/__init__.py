"""The live view and the replay view: one page, one data model, served by the engine."""
