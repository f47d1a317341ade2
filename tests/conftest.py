"""Test-suite settings shared by every module.

Under CI (``CI=true``) hypothesis draws the same examples on every run (``derandomize``), so
a submission's verdict does not depend on luck; a developer's runs keep exploring new
examples (and keep the failures they find in .hypothesis/).
"""

import os

from hypothesis import settings

settings.register_profile('ci', derandomize=True, print_blob=True)
if os.environ.get('CI', '').lower() in ('1', 'true', 'yes'):
    settings.load_profile('ci')
