"""The ready-made viewer setups (config/twodisk.rviz, config/twodisk.foxglove.json) name only
topics and types that the node publishes, in its frame."""

import json
from pathlib import Path
import re

import pytest
import yaml

pytestmark = pytest.mark.ros

REPO = Path(__file__).resolve().parents[1]
RVIZ = REPO / 'config' / 'twodisk.rviz'
FOXGLOVE = REPO / 'config' / 'twodisk.foxglove.json'

#: RViz2 display classes and the message type each one subscribes to
RVIZ_TYPES = {
    'rviz_default_plugins/MarkerArray': 'visualization_msgs/MarkerArray',
    'rviz_default_plugins/Path': 'nav_msgs/Path',
    'rviz_default_plugins/Pose': 'geometry_msgs/PoseStamped',
    'rviz_default_plugins/PointStamped': 'geometry_msgs/PointStamped',
    'rviz_default_plugins/Wrench': 'geometry_msgs/WrenchStamped',
}


def _published():
    """{topic as resolved in the root namespace: 'pkg/Type'} of the node (sampled and latched)."""
    from twodisk_ros.node.frames_publisher import TYPES as LATCHED_TYPES
    from twodisk_ros.node.roller import TOPIC_TYPES
    published = {}
    for topic, kind in {**TOPIC_TYPES, **LATCHED_TYPES}.items():
        published['/' + topic.lstrip('/')] = f'{kind.__module__.split(".")[0]}/{kind.__name__}'
    return published


def _displays(displays):
    for display in displays:
        if display.get('Class') == 'rviz_common/Group':
            yield from _displays(display.get('Displays', []))
        else:
            yield display


def test_rviz_config():
    config = yaml.safe_load(RVIZ.read_text(encoding='utf-8'))
    manager = config['Visualization Manager']
    assert manager['Global Options']['Fixed Frame'] == 'world'
    published = _published()
    seen = {}
    classes = set()
    for display in _displays(manager['Displays']):
        classes.add(display['Class'])
        assert display['Class'].startswith('rviz_default_plugins/'), display['Class']
        if 'Topic' in display:
            topic = display['Topic']['Value']
            assert topic in published, topic
            assert RVIZ_TYPES[display['Class']] == published[topic], (topic, display['Class'])
            seen[topic] = display['Class']
    assert 'rviz_default_plugins/Grid' in classes
    for topic in ('/markers', '/path_a', '/path_b', '/path_g', '/pose'):
        assert topic in seen, topic
    assert all(p['Class'].startswith('rviz_common/') for p in config['Panels'])


_TOPIC = re.compile(r'^(/[A-Za-z0-9_/]+?)(?=[.{\[]|$)')


def test_foxglove_layout():
    layout = json.loads(FOXGLOVE.read_text(encoding='utf-8'))
    assert set(layout) >= {'configById', 'layout', 'globalVariables', 'userNodes',
                           'playbackConfig'}
    panels = layout['configById']

    def ids(node):
        if isinstance(node, str):
            return [node]
        return ids(node['first']) + ids(node['second'])
    assert sorted(ids(layout['layout'])) == sorted(panels)     # every panel is placed
    published = _published()
    kinds = {panel_id.split('!')[0] for panel_id in panels}
    assert {'3D', 'Plot', 'DiagnosticStatusPanel'} <= kinds
    plotted = []
    for panel_id, config in panels.items():
        kind = panel_id.split('!')[0]
        if kind == '3D':
            assert config['followTf'] == 'world'
            assert set(config['topics']) <= set(published), set(config['topics'])
            assert {'/markers', '/path_a', '/path_b', '/path_g', '/pose'} <= set(
                config['topics'])
        elif kind == 'Plot':
            for path in config['paths']:
                topic = _TOPIC.match(path['value']).group(1)
                assert topic in published, path['value']
                plotted.append(path['value'])
        elif kind.startswith('Diagnostic'):
            assert published[config['topicToRender']] == 'diagnostic_msgs/DiagnosticArray'
    assert published['/rolling_state'] == 'sensor_msgs/JointState'
    for k in range(3):                          # theta, psi, phase
        assert f'/rolling_state.position[{k}]' in plotted
    assert any(p.startswith('/diagnostics.') and '"energy"' in p for p in plotted)


def test_setups_are_installed():
    setup = (REPO / 'setup.py').read_text(encoding='utf-8')
    assert "glob('config/*.rviz')" in setup and "glob('config/*.json')" in setup


def test_setups_show_the_robot_model_and_the_tf_tree():
    # RViz: a RobotModel reading the latched (transient-local) robot_description, and TF
    config = yaml.safe_load(RVIZ.read_text(encoding='utf-8'))
    displays = {d['Class']: d for d in _displays(config['Visualization Manager']['Displays'])}
    model = displays['rviz_default_plugins/RobotModel']
    assert model['Enabled'] and model['Description Source'] == 'Topic'
    topic = model['Description Topic']
    assert topic['Value'] == '/robot_description'
    assert _published()[topic['Value']] == 'std_msgs/String'
    assert topic['Durability Policy'] == 'Transient Local'
    assert topic['Reliability Policy'] == 'Reliable'
    assert displays['rviz_default_plugins/TF']['Enabled']
    # Foxglove: the 3D panel shows the URDF of /robot_description (its Urdfs layer reads
    # that topic; hidden unless the topic's settings say visible)
    layout = json.loads(FOXGLOVE.read_text(encoding='utf-8'))
    panel = layout['configById']['3D!twodisk']
    assert panel['topics']['/robot_description']['visible'] is True
    assert panel['topics']['/robot_description']['displayMode'] in ('auto', 'visual')
