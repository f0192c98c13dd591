"""Children's data, private by design (issue 22): the site's data folder and key, and
recordings encrypted at rest with it."""
